"""How the command line speaks on standard error, as grep, git and cp do: one line per error
(``topstoc decimate: error: ...``), one line per warning (``topstoc: warning: ...``), exit 2
for a command line that cannot be parsed and 1 for a failure. OS errors are said in words
naming the file, without ``[Errno N]``.
"""

from __future__ import annotations

import argparse
import errno
import os
import sys

from . import progress

EXIT_FAILURE = 1
EXIT_USAGE = 2

#: OS errors in the words the command line prints (others: the system's text, lower-cased).
OS_ERROR_WORDS = {
    errno.ENOENT: "no such file or directory",
    errno.EISDIR: "is a directory",
    errno.ENOTDIR: "a part of the path is not a directory",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EEXIST: "already exists",
    errno.ENOSPC: "no space left on the device",
    errno.EROFS: "the file system is read-only",
    errno.ENAMETOOLONG: "the name is too long",
    errno.EMFILE: "too many open files",
    errno.EIO: "input/output error",
}


def os_error_text(error: OSError) -> str:
    """``[Errno 21] Is a directory: 'x'`` -> ``x: is a directory``."""
    words = OS_ERROR_WORDS.get(error.errno)
    system = os.strerror(error.errno) if error.errno else None
    if words is None:
        words = (system or type(error).__name__).lower()
    text = error.strerror or words
    if system and system in text:  # a message of ours around the system's words
        text = text.replace(system, words)
    if error.filename is not None:
        target = os.fspath(error.filename)
        if error.filename2 is not None:
            target += f" -> {os.fspath(error.filename2)}"
        if target not in text:
            text = f"{target}: {text}"
    return text


def error_text(error: BaseException) -> str:
    """One line saying what went wrong."""
    if isinstance(error, OSError) and error.errno is not None:
        text = os_error_text(error)
    else:
        text = str(error)
    text = text.strip().splitlines()[0] if text.strip() else type(error).__name__
    return text


def print_error(command: str, text: str) -> None:
    progress.print_line(f"{command}: error: {text}", sys.stderr)


def print_warning(text: str) -> None:
    """``topstoc: warning: text`` on its own line (a progress line is cleared first)."""
    if progress.quiet():
        return
    first = str(text).strip().splitlines()
    progress.print_line(f"topstoc: warning: {first[0] if first else 'warning'}", sys.stderr)


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A ``warnings.showwarning`` that prints the message alone (no source file and line)."""
    print_warning(str(message))


class ArgumentParser(argparse.ArgumentParser):
    """argparse with a one-line usage error: ``topstoc decimate: error: ... (see topstoc decimate
    --help)``, exit 2, instead of the usage dump."""

    #: the name errors start with (default: prog); the Blender batch's prog is a Blender command line
    command = None

    def error(self, message):
        print_error(self.command or self.prog, f"{message} (see '{self.prog} --help')")
        self.exit(EXIT_USAGE)
