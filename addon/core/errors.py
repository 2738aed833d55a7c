"""TopStoc's error base class, and how any error reads to the user: one line naming its file."""

import os


class TopStocError(ValueError):
    """A request TopStoc cannot carry out; the message names the problem.

    It is a ValueError, so code that catches ValueError keeps working. The add-on's errors
    (DecimationError, GuidanceError, AnalysisError, EditError, MetricsError) derive from it,
    so one ``except TopStocError`` catches any of them.
    """


def shown_path(path) -> str:
    """A file name as text anyone can read: bytes that are not UTF-8 shown as ``\\xe9``."""
    return os.fsencode(path).decode("utf-8", "backslashreplace")


def _system_reason(error: BaseException):
    """The system's reason for an OSError in lower case ("is a directory"), else None."""
    if isinstance(error, OSError) and error.errno is not None and error.strerror == os.strerror(error.errno):
        return error.strerror[:1].lower() + error.strerror[1:]
    return None


def one_line(error: BaseException) -> str:
    """The first line of ``error``'s message; an OSError from the system as ``FILE: reason``
    ("x.obj: is a directory"), without Python's ``[Errno N]`` prefix."""
    reason = _system_reason(error)
    if reason is not None:
        return reason if error.filename is None else f"{shown_path(error.filename)}: {reason}"
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__
