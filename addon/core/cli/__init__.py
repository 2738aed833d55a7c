"""Command line: ``python3 -m topstoc SUBCOMMAND ...`` (docs/design.md §6).

Each subcommand lives in its own module here and provides ``add_parser(subparsers)`` and
``run(args) -> int``. Errors print one clear line on standard error and exit non-zero.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import warnings

from ..errors import one_line

# Subcommand modules, in the order --help lists them.
SUBCOMMANDS = ("decimate", "batch", "measure", "topology", "loops", "edit")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python3 -m topstoc",
                                     description="TopStoc: guided decimation with topology control.")
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


def print_json(data) -> None:
    """Prints a JSON document (numpy scalars and arrays converted)."""
    def convert(value):
        if hasattr(value, "tolist"):
            return value.tolist()
        raise TypeError(f"cannot write {type(value).__name__} as JSON")
    json.dump(data, sys.stdout, indent=2, default=convert)
    sys.stdout.write("\n")


def show_warnings_as_lines(command: str) -> None:
    """Warnings (e.g. a MeshFileWarning: what a reader skipped) print as one line each on
    standard error, named after the command, instead of Python's two-line file:line form."""
    def show(message, category, filename, lineno, file=None, line=None):
        text = str(message).splitlines()[0] if str(message) else category.__name__
        print(f"topstoc {command}: warning: {text}", file=sys.stderr if file is None else file)
    warnings.showwarning = show


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    show_warnings_as_lines(args.command)
    try:
        return int(args.run(args) or 0)
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): stop quietly, as Unix tools do.
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (ValueError, OSError, RuntimeError) as error:
        print(f"topstoc {args.command}: error: {one_line(error)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"topstoc {args.command}: interrupted", file=sys.stderr)
        return 130
