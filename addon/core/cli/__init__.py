"""Command line: ``python3 -m topstoc SUBCOMMAND ...`` (docs/design.md §6).

Each subcommand lives in its own module here and provides ``add_parser(subparsers)`` and
``run(args) -> int``. Errors print one clear line on standard error and exit 1 (2 for a command
line that cannot be parsed); warnings one line each (topstoc.core.cli.messages). Commands with
``--progress`` / ``--quiet`` get a progress line for jobs over a second (topstoc.core.cli.progress).
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import warnings

from . import messages, progress


# Subcommand modules, in the order --help lists them.
SUBCOMMANDS = ("decimate", "batch", "measure", "topology", "loops", "edit", "clean")


def build_parser() -> argparse.ArgumentParser:
    from ... import __version__

    parser = messages.ArgumentParser(prog="topstoc",
                                     description="TopStoc: guided decimation with topology control. "
                                                 "Run as `topstoc` (pip) or `python3 -m topstoc`.")
    parser.add_argument("--version", action="version", version=f"topstoc {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="SUBCOMMAND")
    subparsers.required = True
    for name in SUBCOMMANDS:
        try:
            module = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as error:
            if error.name == f"{__name__}.{name}":
                continue  # not part of this build
            raise
        module.add_parser(subparsers)
    return parser


def subcommand(subparsers, name: str, summary: str, description: str, *files) -> argparse.ArgumentParser:
    """A subcommand's parser (``summary`` for the list, ``description`` for its --help) with its
    positional file arguments, each ``(name, metavar, help)``, in order."""
    parser = subparsers.add_parser(name, help=summary, description=description)
    for dest, metavar, text in files:
        parser.add_argument(dest, metavar=metavar, help=text)
    return parser


def print_json(data) -> None:
    """Prints a JSON document (numpy scalars and arrays converted)."""
    def convert(value):
        if hasattr(value, "tolist"):
            return value.tolist()
        raise TypeError(f"cannot write {type(value).__name__} as JSON")
    json.dump(data, sys.stdout, indent=2, default=convert)
    sys.stdout.write("\n")


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    command = f"topstoc {args.command}"
    wants = getattr(args, "progress", None)  # batch has its own progress (a bar or lines)
    progress.set_quiet(getattr(args, "quiet", False))
    try:
        with warnings.catch_warnings():
            warnings.showwarning = messages.show_warning
            stdout = sys.stdout
            if isinstance(wants, bool) and progress.start(
                    command, forced=wants, quiet=progress.quiet() or getattr(args, "json", False) is True):
                sys.stdout = progress.StopOnOutput(stdout)
            try:
                return int(args.run(args) or 0)
            finally:
                progress.stop()
                sys.stdout = stdout
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): stop quietly, as Unix tools do.
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (ValueError, OSError, RuntimeError) as error:
        messages.print_error(command, messages.error_text(error))
        return messages.EXIT_FAILURE
    except KeyboardInterrupt:
        messages.print_error(command, "interrupted")
        return 130
