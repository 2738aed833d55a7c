"""Loads the compiled engine `_topstoc` that the build places next to this package."""

import os

# Idle OpenMP threads sleep instead of spinning: spinning threads look busy to the engine's
# free-core count (and to everyone else's). Only takes effect if libgomp is not loaded yet
# (plain Python, bpy 4.x); Debian's Blender loads it first. A user's setting wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

try:
    from .. import _topstoc as engine
except ImportError as error:  # pragma: no cover - only without a build
    raise ImportError(
        "topstoc's compiled module _topstoc is missing or does not match this Python "
        "(it is built for CPython 3.11): build it with "
        "'cmake -S . -B build && cmake --build build' and use build/python/topstoc"
    ) from error

__all__ = ["engine"]
