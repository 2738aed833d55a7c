"""Loads the compiled engine `_topstoc` that the build places next to this package."""

try:
    from .. import _topstoc as engine
except ImportError as error:  # pragma: no cover - only without a build
    raise ImportError(
        "topstoc's compiled module _topstoc is missing or does not match this Python "
        "(it is built for CPython 3.11): build it with "
        "'cmake -S . -B build && cmake --build build' and use build/python/topstoc"
    ) from error

__all__ = ["engine"]
