"""Flags of a Blender mesh's elements: seams, sharp edges, selection and hiding.

Blender 4.0+ keeps them as attributes that exist only while some element has the flag, 3.x as
bits of its element structs. The seam and sharp flags a result carries follow the input's flagged
curves (topstoc.core.carry.edge_flags decides which output edges they mark).
"""

from __future__ import annotations

import bpy
import numpy as np

from ...core.carry.edge_flags import carried_edge_flags
from . import dna_arrays
from .mesh_access import DOMAIN_COLLECTIONS, attribute_for_write, first_attribute, read_array


def read_edges(mesh: bpy.types.Mesh, flag: str) -> np.ndarray:
    """(k, 2) vertex pairs of the edges whose boolean ``flag`` is set (use_seam, use_edge_sharp).

    Blender 4.0+ keeps these flags as edge attributes that exist only when some edge has the
    flag: none means no read at all (a flag per edge through MeshEdge is a large part of the Live
    Preview's start); 3.x copies them from its edge array
    (dna_arrays.flagged_edges)."""
    count = len(mesh.edges)
    attribute = _flag_attribute(mesh, flag) if bpy.app.version >= (4, 0, 0) else None
    if bpy.app.version >= (4, 0, 0) and (attribute is None or flag in mistyped_edge_flags(mesh)):
        if attribute is None:
            return np.zeros((0, 2), dtype=np.int32)
        attribute = None  # mistyped by Blender 5.0's edge pass: read through MeshEdge instead
    if attribute is not None:
        flags = read_array(attribute.data, "value", count, 1, bool)
    else:
        pairs = dna_arrays.flagged_edges(mesh, flag)
        if pairs is not None:
            return pairs
        flags = read_array(mesh.edges, flag, count, 1, bool)
    if not flags.any():
        return np.zeros((0, 2), dtype=np.int32)
    edges = read_array(mesh.edges, "vertices", count, 2, np.int32)
    return edges[flags]


# Edge flags (MeshEdge properties) Blender keeps as edge attributes: their names (seams are
# ".uv_seam" in 4.0-4.4 and "uv_seam" from 4.5: Blender 4.2 and 4.3 show the first, 4.5 the second)
# and the type each must have.
_EDGE_FLAG_ATTRIBUTES = {"select": ((".select_edge",), "BOOLEAN"), "hide": ((".hide_edge",), "BOOLEAN"),
                         "use_seam": ((".uv_seam", "uv_seam"), "BOOLEAN"),
                         "use_edge_sharp": (("sharp_edge",), "BOOLEAN"),
                         "use_freestyle_mark": (("freestyle_edge",), "BOOLEAN"),
                         "crease": (("crease_edge",), "FLOAT"), "bevel_weight": (("bevel_weight_edge",), "FLOAT")}


CARRIED_EDGE_FLAGS = ("use_seam", "use_edge_sharp")


# Element flags by domain that Blender 4.0+ keeps as attributes, present only while some element
# has the flag (MeshVertex.select and the like go one element at a time there): their names
# and type. Freestyle marks are not
# among them: 4.x keeps them in layers of their own, and 5.0 has no such property.
ELEMENT_FLAG_ATTRIBUTES = {
    "POINT": {"select": ((".select_vert",), "BOOLEAN"), "hide": ((".hide_vert",), "BOOLEAN")},
    "EDGE": {flag: names for flag, names in _EDGE_FLAG_ATTRIBUTES.items() if flag != "use_freestyle_mark"},
    "FACE": {"select": ((".select_poly",), "BOOLEAN"), "hide": ((".hide_poly",), "BOOLEAN")},
}


def read_element_flag(mesh: bpy.types.Mesh, domain: str, flag: str) -> np.ndarray:
    """``flag`` ("select" or "hide") of every element of ``domain`` (POINT, EDGE, FACE) as bools."""
    collection = getattr(mesh, DOMAIN_COLLECTIONS[domain])
    if bpy.app.version < (4, 0, 0):
        return read_array(collection, flag, len(collection), 1, bool)
    attribute = element_flag_attribute(mesh, domain, flag)
    if attribute is None or (attribute.domain, attribute.data_type) != (domain, "BOOLEAN"):
        return np.zeros(len(collection), dtype=bool)  # none flagged, or mistyped (mistyped_edge_flags)
    return read_array(attribute.data, "value", len(collection), 1, bool)


def element_flag_attribute(mesh: bpy.types.Mesh, domain: str, flag: str):
    """The attribute that holds ``flag`` (one of ELEMENT_FLAG_ATTRIBUTES) of ``domain``'s elements
    in Blender 4.0+, None when there is none: no element has the flag."""
    return first_attribute(mesh, ELEMENT_FLAG_ATTRIBUTES[domain][flag][0])


def read_carried_edge_flags(source: bpy.types.Mesh) -> dict:
    """{flag: (k, 2) flagged input vertex pairs} of the edge flags a result carries."""
    return {flag: read_edges(source, flag) for flag in CARRIED_EDGE_FLAGS}


def output_edge_flags(flagged: dict, edges: np.ndarray, kept, moved=None) -> dict:
    """{flag: bool per output edge} for ``read_carried_edge_flags``' input flags (core/carry/edge_flags.py's
    rule; ``moved``: output vertices not at their input vertex); flags set nowhere are left out.
    Touches no Blender data (the preview calls it on a worker)."""
    out = {}
    for flag, pairs in flagged.items():
        if len(pairs):
            values = carried_edge_flags(pairs, edges, kept, moved)
            if values.any():
                out[flag] = values
    return out


def carry_edge_flags(source: bpy.types.Mesh, out: bpy.types.Mesh, kept, moved=None) -> None:
    """Sets the seam and sharp flags of ``out``'s edges (a result of ``source``; output vertex i
    stands for input vertex kept[i]) where they follow a flagged input curve."""
    flagged = read_carried_edge_flags(source)
    if len(out.edges) and any(len(pairs) for pairs in flagged.values()):
        edges = read_array(out.edges, "vertices", len(out.edges), 2, np.int32)
        write_edge_flags(out, output_edge_flags(flagged, edges, kept, moved))


def write_edge_flags(mesh: bpy.types.Mesh, flags: dict) -> None:
    """Writes boolean edge flags ({flag: bool per edge}: use_seam, use_edge_sharp) of a mesh whose
    edges carry none yet. Blender 4.0+ keeps them as edge attributes (".uv_seam", 4.5+ "uv_seam";
    "sharp_edge") made here; 3.x as bits of its edges, written through MeshEdge."""
    for flag, values in flags.items():
        values = np.ascontiguousarray(values, dtype=bool)
        if bpy.app.version < (4, 0, 0):
            mesh.edges.foreach_set(flag, values)
            continue
        existing = _flag_attribute(mesh, flag)  # a mistyped one (mistyped_edge_flags) is made anew
        names = _EDGE_FLAG_ATTRIBUTES[flag][0]
        name = existing.name if existing is not None else names[-1] if bpy.app.version >= (4, 5, 0) else names[0]
        attribute_for_write(mesh, name, "BOOLEAN", "EDGE").data.foreach_set("value", values)


def _flag_attribute(mesh: bpy.types.Mesh, flag: str):
    """The attribute that holds edge ``flag`` in this Blender, None when there is none."""
    return first_attribute(mesh, _EDGE_FLAG_ATTRIBUTES[flag][0])


def mistyped_edge_flags(mesh: bpy.types.Mesh) -> dict:
    """{edge flag: its attribute} for flags whose attribute has the wrong domain or type.

    Blender 5.0.x's edge pass (``update(calc_edges=True)``, ``from_pydata``) gives ``.select_edge``
    the type of ``.edge_verts`` (INT32_2D): reading ``MeshEdge.select`` then gives garbage and
    writing it crashes Blender. Such flags are neither read nor written.
    """
    found = {}
    for flag, (_names, data_type) in _EDGE_FLAG_ATTRIBUTES.items():
        attribute = _flag_attribute(mesh, flag)
        if attribute is not None and (attribute.domain != "EDGE" or attribute.data_type != data_type):
            found[flag] = attribute
    return found


def calc_edges(mesh: bpy.types.Mesh, calc: bool = True) -> None:
    """``mesh.update(calc_edges=calc)``, then removes edge-flag attributes it left mistyped (see
    :func:`mistyped_edge_flags`). Nothing is lost: fresh edges carry no flags, and a later write
    creates the attribute with the right type."""
    mesh.update(calc_edges=calc)
    for attribute in mistyped_edge_flags(mesh).values():
        mesh.attributes.remove(attribute)
