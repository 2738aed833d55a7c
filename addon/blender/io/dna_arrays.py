"""Mesh arrays read in one pass from the DNA structs behind them.

Blender 3.x keeps edges, loops and polygons as arrays of C structs (MEdge, MLoop, MPoly); every
version keeps a shape key's positions as one float array (KeyBlock.data) and a byte colour
attribute as one array of 4 bytes an element. foreach_get copies a field out of them element by
element, which on a large mesh was most of the Live Preview's start (loops' vertex ids, seam
flags, a shape key, a painted guidance layer's colours). Here the array is viewed at the first
element's address and the fields are copied out with numpy.

A view is used only when the array looks like the layout below: its elements are contiguous
with the struct's size, and at sampled elements every field read here equals what RNA gives.
Otherwise (another Blender, another layout) the functions return None and the caller reads
through RNA. The view is checked before anything is copied out of it, and every result is a
copy: nothing keeps pointing into Blender's memory.

Writing goes the same way for the geometry of a new 3.x mesh (loops, polygons, edges), which
foreach_set also fills field by field (about a third of writing a Live Preview frame in 3.4).
A fresh array holds zeros, so its layout is
probed instead: values set through RNA at its first and last elements must show in the view's
fields before anything is written through it; otherwise the functions write nothing and return
False, and the caller uses foreach_set.
"""

from __future__ import annotations

import ctypes
from typing import Optional

import bpy
import numpy as np

from ...core.support import fresh_memory

# DNA_meshdata_types.h in 3.x
MEDGE = np.dtype([("v", "<u4", 2), ("crease", "u1"), ("bweight", "u1"), ("flag", "<i2")])
MLOOP = np.dtype([("v", "<u4"), ("e", "<u4")])
MPOLY = np.dtype([("loopstart", "<i4"), ("totloop", "<i4"), ("mat_nr", "<i2"), ("flag", "u1"), ("pad", "u1")])
KEY_POINT = np.dtype([("co", "<f4", 3)])  # a shape key's positions: float[3] per point
EDGE_FLAG_BITS = {"use_seam": 1 << 2, "use_edge_sharp": 1 << 9}  # ME_SEAM, ME_SHARP
LAYOUT_SAMPLES = 64
# Elements a field is scanned by at a time where only a few results or a yes / no come out of it.
# A temporary as long as the mesh is fresh memory, and fresh memory costs a page fault every 4 KB:
# in Blender 3.4, whose allocator hands freed pages back to the kernel, the faults of the
# Live Preview's start took longer than its copying.
SCAN_BLOCK = 1 << 16


def _view(collection, dtype: np.dtype, legacy: bool = True) -> Optional[np.ndarray]:
    """The struct array behind ``collection`` as a numpy view (valid until Blender changes the
    mesh: callers copy out of it at once), or None when it is not contiguous, or outside 3.x for
    the ``legacy`` mesh structs."""
    count = len(collection)
    if (legacy and not (3, 0, 0) <= bpy.app.version < (4, 0, 0)) or count < 2:
        return None
    first = collection[0].as_pointer()
    if collection[1].as_pointer() - first != dtype.itemsize or \
            collection[count - 1].as_pointer() - first != dtype.itemsize * (count - 1):
        return None
    return np.frombuffer((ctypes.c_char * (dtype.itemsize * count)).from_address(first), dtype=dtype)


def _checked_view(collection, dtype: np.dtype, fields: dict, legacy: bool = True) -> Optional[np.ndarray]:
    """``_view``, when at every sampled element each of ``fields`` ({view field: RNA property})
    equals what RNA gives; else None."""
    raw = _view(collection, dtype, legacy)
    if raw is None:
        return None
    for i in _samples(len(raw)):
        element = collection[i]
        for field, prop in fields.items():
            if not np.array_equal(np.asarray(getattr(element, prop), dtype=np.float64), raw[field][i]):
                return None
    return raw


def _samples(count: int, extra=()) -> list:
    """Elements whose fields are compared with RNA's: spread over the array, plus ``extra``."""
    spread = np.unique(np.linspace(0, count - 1, LAYOUT_SAMPLES).astype(np.int64)).tolist()
    return spread + [int(i) for i in extra]


def _probed_view(collection, dtype: np.dtype, field: str, prop: str) -> Optional[np.ndarray]:
    """``_view`` of a 3.x struct array about to be overwritten, when small values set through
    RNA's ``prop`` at its first and last elements show in the view's ``field``; else None."""
    raw = _view(collection, dtype)
    if raw is None:
        return None
    shape = dtype[field].shape
    for i, first in ((0, 1), (len(raw) - 1, 1 + max(1, int(np.prod(shape))))):
        probe = list(range(first, first + int(np.prod(shape)))) if shape else first
        try:
            setattr(collection[i], prop, probe)
        except (AttributeError, TypeError, ValueError):  # read-only or ranged elsewhere
            return None
        if raw[field][i].tolist() != probe:
            return None
    return raw


# RNA index property -> the 3.x struct and field behind it (the names are unique across loops,
# edges and polygons).
STRUCT_FIELDS = {"vertex_index": (MLOOP, "v"), "edge_index": (MLOOP, "e"), "vertices": (MEDGE, "v"),
                 "loop_start": (MPOLY, "loopstart"), "loop_total": (MPOLY, "totloop")}


def write_field(collection, prop: str, values: np.ndarray) -> bool:
    """Sets ``prop`` (a key of STRUCT_FIELDS) of every element of a 3.x loop, edge or polygon
    array to ``values`` (flat, or one row per element) in one pass; False when it wrote nothing."""
    dtype, field = STRUCT_FIELDS[prop]
    raw = _probed_view(collection, dtype, field, prop)
    if raw is None:
        return False
    raw[field] = np.reshape(values, raw[field].shape)
    return True


def flagged_edges(mesh: bpy.types.Mesh, flag: str) -> Optional[np.ndarray]:
    """(k, 2) int32 vertex pairs of the edges whose ``flag`` ("use_seam" or "use_edge_sharp") is
    set, in edge order, from MEdge.flag and MEdge.v."""
    raw = _view(mesh.edges, MEDGE) if flag in EDGE_FLAG_BITS else None
    if raw is None:
        return None
    bits, field = EDGE_FLAG_BITS[flag], raw["flag"]
    found = [np.flatnonzero(field[start:start + SCAN_BLOCK] & bits) + start
             for start in range(0, len(field), SCAN_BLOCK)]
    flagged = np.concatenate(found)
    for i in _samples(len(raw), flagged[:LAYOUT_SAMPLES]):
        edge = mesh.edges[i]
        if tuple(edge.vertices) != tuple(raw["v"][i].tolist()) or getattr(edge, flag) != bool(field[i] & bits):
            return None
    return raw["v"][flagged].astype(np.int32)


def loop_indices(mesh: bpy.types.Mesh, field: str) -> Optional[np.ndarray]:
    """(loops,) int32 vertex ("v") or edge ("e") of every loop, from MLoop."""
    raw = _checked_view(mesh.loops, MLOOP, {"v": "vertex_index", "e": "edge_index"})
    if raw is None:
        return None
    out = fresh_memory.empty(len(raw), np.int32)
    np.copyto(out, raw[field], casting="unsafe")  # (uint32 ids below 2^31: the same values)
    return out


def triangles_in_loop_order(mesh: bpy.types.Mesh) -> Optional[bool]:
    """Whether polygon i starts at loop 3 i for every i, read off MPoly.loopstart without copying
    it; None when the array cannot be viewed. (Its material slot is not read: 3.4 keeps that in
    the "material_index" attribute and leaves MPoly.mat_nr 0.)"""
    raw = _checked_view(mesh.polygons, MPOLY, {"loopstart": "loop_start", "totloop": "loop_total"})
    return every_third(raw["loopstart"]) if raw is not None else None


def every_third(starts: np.ndarray) -> bool:
    """starts[i] == 3 i for every i, compared a block at a time."""
    step = np.arange(0, 3 * SCAN_BLOCK, 3, dtype=np.int64)
    for start in range(0, len(starts), SCAN_BLOCK):
        part = starts[start:start + SCAN_BLOCK]
        if not np.array_equal(part, step[:len(part)] + 3 * start):
            return False
    return True


def shape_key_positions(block) -> Optional[np.ndarray]:
    """(n, 3) float32 positions of a shape key (a KeyBlock), from its float array."""
    raw = _checked_view(block.data, KEY_POINT, {"co": "co"}, legacy=False)
    return raw.view(np.float32).reshape(-1, 3).copy() if raw is not None else None  # (a field copy is slower)


def byte_colors_srgb(attribute) -> Optional[np.ndarray]:
    """(count, 4) float32 stored sRGB values of a byte colour attribute, as ``color_srgb`` gives
    them (each byte / 255), from its array of 4 bytes an element."""
    raw = _view(attribute.data, np.dtype(("u1", 4)), legacy=False)
    if raw is None:
        return None
    values = raw.astype(np.float32) / np.float32(255)
    for i in _samples(len(raw)):
        if tuple(attribute.data[i].color_srgb) != tuple(values[i].tolist()):
            return None
    return values
