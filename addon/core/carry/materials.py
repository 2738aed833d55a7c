"""An OBJ's material libraries (``mtllib``) and their textures, carried to a written copy.

A decimated OBJ written into another folder gets its .mtl files copied beside it (at the same
relative path as beside the input) with the textures they name, so that the output folder opens
on its own in Blender or any viewer. Nothing existing is overwritten: a file already at the
destination with the same bytes is used as is; one with other bytes is left alone and the output
refers to the input's file instead (by a path relative to the output), with a warning. Libraries
or textures given by absolute paths, or missing beside the input, are referenced as they are; a
library naming a texture above its own folder (``../``) is not copied but referred to.
"""

from __future__ import annotations

import filecmp
import os
import re
import shutil
import warnings

#: .mtl statements whose last word is a file (texture maps, bump, displacement, reflection)
TEXTURE_STATEMENTS = re.compile(r"^\s*(map_\w+|bump|disp|decal|refl|norm)\s+(.*\S)\s*$", re.IGNORECASE)


class MaterialFileWarning(UserWarning):
    """A material library or texture could not be copied beside the output (the message says why)."""


def _inside(relative: str) -> bool:
    """A relative path that stays below its folder (no ``..``, not absolute)."""
    return not os.path.isabs(relative) and not relative.replace("\\", "/").startswith("../") \
        and ".." not in relative.replace("\\", "/").split("/")


def _copy_new(source: str, destination: str) -> bool:
    """Copies source to destination unless a different file is there; True when destination now
    holds source's bytes. The copy is atomic (temporary name, then rename)."""
    if os.path.exists(destination):
        return os.path.isfile(destination) and filecmp.cmp(source, destination, shallow=False)
    os.makedirs(os.path.dirname(destination) or ".", exist_ok=True)
    temporary = f"{destination}.tmp{os.getpid()}"
    try:
        shutil.copyfile(source, temporary)
        os.replace(temporary, destination)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)
    return True


def _textures(library: str) -> list:
    """The texture paths a .mtl file names (options such as ``-s 1 1 1`` come first): the longest
    tail of each map statement that is a file beside the library, else its last word."""
    here = os.path.dirname(library)
    found = []
    with open(library, "r", encoding="utf-8", errors="replace") as stream:
        for line in stream:
            match = TEXTURE_STATEMENTS.match(line)
            if not match:
                continue
            words = match.group(2).replace("\\", "/").split()  # Windows exporters write .\name.jpg
            tails = [" ".join(words[i:]) for i in range(len(words))]
            found.append(next((t for t in tails if os.path.isfile(os.path.join(here, t))), words[-1]))
    return found


def _reference(path: str, output_dir: str) -> str:
    return os.path.relpath(path, output_dir).replace(os.sep, "/")


def carry_libraries(libraries, source: str, destination: str) -> list:
    """The ``mtllib`` names for an OBJ written to ``destination`` from one read at ``source``,
    after copying the libraries and their textures beside it when the folders differ (see the
    module docs)."""
    source_dir = os.path.dirname(os.path.abspath(source))
    output_dir = os.path.dirname(os.path.abspath(destination))
    if os.path.normcase(source_dir) == os.path.normcase(output_dir):
        return list(libraries)
    names = []
    for library in libraries:
        original = os.path.join(source_dir, library)
        if os.path.isabs(library) or not os.path.isfile(original):
            names.append(library)
            continue
        if not _inside(library) or not _carry(original, os.path.join(output_dir, library)):
            names.append(_reference(original, output_dir))  # the input's own library
            continue
        names.append(library)
    return names


def _carry(library: str, copy: str) -> bool:
    """Copies a .mtl and the relative textures it names (kept below its folder); False when a
    different file already stands at the library's destination (nothing of it copied then)."""
    if os.path.exists(copy) and not (os.path.isfile(copy) and filecmp.cmp(library, copy, shallow=False)):
        warnings.warn(f"{copy}: a different file already exists; the output refers to {library} instead",
                      MaterialFileWarning, stacklevel=3)
        return False
    here, there = os.path.dirname(library), os.path.dirname(copy)
    textures = [t for t in _textures(library) if not os.path.isabs(t) and os.path.isfile(os.path.join(here, t))]
    if not all(_inside(t) for t in textures):
        return False  # a texture above the library's folder: a copy would lose it, refer to the input's
    for texture in textures:
        original = os.path.join(here, texture)
        if not _copy_new(original, os.path.join(there, texture)):
            warnings.warn(f"{os.path.join(there, texture)}: a different file already exists; left as it is",
                          MaterialFileWarning, stacklevel=3)
    _copy_new(library, copy)
    return True
