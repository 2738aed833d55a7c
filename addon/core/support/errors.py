"""TopStoc's error base class, and how any error reads to the user: one line naming its file."""

import errno
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


#: OS errors in words where the system's own text reads oddly (others: its text, lower-cased).
OS_ERROR_WORDS = {errno.EEXIST: "already exists", errno.ENOTDIR: "a part of the path is not a directory"}


def _os_error_text(error: OSError) -> str:
    """``[Errno 21] Is a directory: 'x'`` -> ``x: is a directory``; a message of ours that
    carries an errno keeps its words, with the system's part said the same way."""
    system = os.strerror(error.errno)
    words = OS_ERROR_WORDS.get(error.errno) or system[:1].lower() + system[1:]
    text = error.strerror if error.strerror is not None else (str(error) or words)
    text = text.replace(system, words)
    if error.filename is not None:
        target = shown_path(error.filename)
        if error.filename2 is not None:
            target += f" -> {shown_path(error.filename2)}"
        if target not in text:
            text = f"{target}: {text}"
    return text


def one_line(error: BaseException) -> str:
    """The first line of ``error``'s message; an OSError from the system as ``FILE: reason``
    ("x.obj: is a directory"), without Python's ``[Errno N]`` prefix."""
    text = _os_error_text(error) if isinstance(error, OSError) and error.errno is not None else str(error)
    text = text.strip()
    return text.splitlines()[0] if text else type(error).__name__
