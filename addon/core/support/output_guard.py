"""Outputs that would destroy inputs are refused before any work (docs/design.md §6.1).

A command never writes over one of its inputs, and a batch never writes into a folder it reads
inputs from (nor reads inputs from inside its output folder): a rerun would take its outputs as
new inputs and decimate them again. Paths are compared as the files they are: ``IN`` and
``./IN``, ``sub/../IN``, a symlink and its target and two hard links of one file are the same
file; folders are compared by device and inode, so a bind mount is caught too. Every refusal is
a TopStocError of one line naming both paths.
"""

from __future__ import annotations

import os

from . import atomic
from .errors import TopStocError, shown_path


def file_identity(path):
    """(device, inode) of what ``path`` names, symlinks followed; None when it does not exist."""
    try:
        status = os.stat(path)
    except (OSError, ValueError):
        return None
    return status.st_dev, status.st_ino


def identities(paths) -> dict:
    """{(device, inode): path} of those ``paths`` that exist (the last path given for each file)."""
    found = {}
    for path in paths:
        identity = file_identity(path)
        if identity is not None:
            found[identity] = path
    return found


def same_file(a, b) -> bool:
    """Whether ``a`` and ``b`` name one file (or would: a missing file is compared by its real path)."""
    first, second = file_identity(a), file_identity(b)
    if first is not None and second is not None:
        return first == second
    return os.path.realpath(a) == os.path.realpath(b)


def _folders_holding(path) -> list:
    """Identities of the folders ``path`` lies in (its real path's parents, innermost first)."""
    found, current = [], os.path.realpath(path)
    while True:
        parent = os.path.dirname(current)
        if parent == current:
            return found
        current = parent
        identity = file_identity(current)
        if identity is not None:
            found.append(identity)


def prepare_output(output, inputs, *, overwrite: bool = False) -> None:
    """Refuses ``output`` when it is one of ``inputs`` (None entries, and a None output, skipped),
    then removes the temporary files killed writers of it left (atomic.sweep). ``overwrite``
    allows replacing the first input, the one file a single-file command transforms."""
    if output is None:
        return
    for index, given in enumerate(inputs):
        if given is None or not same_file(given, output):
            continue
        if overwrite and index == 0:
            continue
        alias = "" if os.path.abspath(given) == os.path.abspath(output) else f" {shown_path(given)}"
        hint = ", or pass --overwrite to replace the input" if index == 0 else ""
        raise TopStocError(f"{shown_path(output)}: the output is the input file{alias}; write to another file{hint}")
    atomic.sweep(output)


def check_folders(inputs, out_dir) -> None:
    """Refuses an output folder that is an input folder, lies inside one, or holds an input."""
    out = file_identity(out_dir)
    out_parents = _folders_holding(out_dir)
    for given in inputs:
        name, folder = shown_path(given), shown_path(out_dir)
        if os.path.isdir(given):
            identity = file_identity(given)
            if identity == out:
                raise TopStocError(f"--output {folder} is the input folder {name}: a rerun would read the outputs "
                                   "as inputs; write to a folder outside it")
            if identity in out_parents:
                raise TopStocError(f"--output {folder} lies inside the input folder {name}: a rerun would read the "
                                   "outputs as inputs; write to a folder outside it")
        if out is not None and out in _folders_holding(given):
            raise TopStocError(f"the input {name} lies inside --output {folder}: outputs must go to a folder that "
                               "holds no input")


def check_outputs(outputs, inputs) -> None:
    """Refuses when an existing output file is one of ``inputs`` under another name (a hard link)."""
    taken = identities(inputs)
    for output in outputs:
        given = taken.get(file_identity(output))
        if given is not None:
            raise TopStocError(f"{shown_path(output)}: is the input {shown_path(given)} (the same file); "
                               "write to another folder")


def output_folder(out_dir) -> None:
    """Creates the output folder; one line when a file is in the way."""
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise TopStocError(f"--output {shown_path(out_dir)}: is a file, not a folder")
    os.makedirs(out_dir, exist_ok=True)


def add_overwrite_argument(parser) -> None:
    """The single-file commands' --overwrite option."""
    parser.add_argument("--overwrite", action="store_true",
                        help="allow OUT to be IN (the input is replaced, atomically)")
