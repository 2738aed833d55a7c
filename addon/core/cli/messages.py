"""How the command line speaks on standard error, as grep, git and cp do: one line per error
(``topstoc decimate: error: ...``), one line per warning (``topstoc: warning: ...``), exit 2
for a command line that cannot be parsed and 1 for a failure. OS errors are said in words
naming the file, without ``[Errno N]``.
"""

from __future__ import annotations

import argparse
import sys

from . import progress
from ..support.errors import one_line

EXIT_FAILURE = 1
EXIT_USAGE = 2

#: One line saying what went wrong (core/support/errors.py: OS errors in words, naming the file).
error_text = one_line


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
