"""A Blender mesh's UV maps, generic attributes and vertex-group weights as arrays.

UV maps and attributes are read and written whole (foreach_get / foreach_set); vertex-group
weights, which Blender has no bulk accessor for, sparsely (read_vertex_weights,
write_vertex_weights).
"""

from __future__ import annotations

from typing import Optional

import bpy
import numpy as np

from ...core.carry.attributes import SparseWeights
from ...core.support.ranges import matching_rows
from . import dna_arrays
from .mesh_access import read_array, typed_attribute


# Attribute data type -> (foreach key, values per element, numpy dtype)
_ATTRIBUTE_LAYOUT = {
    "FLOAT": ("value", 1, np.float32),
    "INT": ("value", 1, np.int32),
    "INT8": ("value", 1, np.int8),
    "BOOLEAN": ("value", 1, bool),
    "FLOAT2": ("vector", 2, np.float32),
    "FLOAT_VECTOR": ("vector", 3, np.float32),
    "FLOAT_COLOR": ("color", 4, np.float32),
    "BYTE_COLOR": ("color", 4, np.float32),
    "INT32_2D": ("value", 2, np.int32),
    "QUATERNION": ("value", 4, np.float32),
}


# Attributes written through dedicated paths (positions, topology, materials, smoothing).
SKIPPED_ATTRIBUTES = {"position", "material_index", "sharp_face", "sharp_edge", "normal"}


# Attribute types whose values a moved vertex interpolates (the others take the nearest corner's).
INTERPOLATED = {"FLOAT", "FLOAT2", "FLOAT_VECTOR", "FLOAT_COLOR", "BYTE_COLOR"}


def _uv_attribute(mesh, name: str):
    """The float2 corner attribute Blender 3.5+ keeps a UV map in, whose foreach_get/set copy it
    at once (MeshUVLoop.uv goes one corner at a time in 4.5, tens of times slower); None before
    3.5."""
    if bpy.app.version < (3, 5, 0):
        return None
    return typed_attribute(mesh, name, "CORNER", "FLOAT2")


def read_uv_maps(mesh: bpy.types.Mesh) -> dict:
    """{name: (num_loops, 2) float32} for every UV map."""
    return {uv.name: read_uv_map(mesh, uv.name) for uv in mesh.uv_layers}


def read_uv_map(mesh: bpy.types.Mesh, name: str) -> np.ndarray:
    """(num_loops, 2) float32 UVs of one UV map."""
    attribute = _uv_attribute(mesh, name)
    if attribute is not None:
        return read_array(attribute.data, "vector", len(mesh.loops), 2, np.float32)
    return read_array(mesh.uv_layers[name].data, "uv", len(mesh.loops), 2, np.float32)


def write_uv_map(mesh: bpy.types.Mesh, name: str, values: np.ndarray) -> None:
    """Sets the UV map ``name`` of ``mesh`` (made when missing) to ``values``, one row per loop."""
    layer = mesh.uv_layers.get(name) or mesh.uv_layers.new(name=name, do_init=False)
    if not len(values):
        return
    flat = np.ascontiguousarray(values, dtype=np.float32).ravel()
    attribute = _uv_attribute(mesh, layer.name)
    if attribute is not None:
        attribute.data.foreach_set("vector", flat)
    else:
        layer.data.foreach_set("uv", flat)


def read_attribute(attribute, count: int) -> Optional[np.ndarray]:
    """(values as (count, width), foreach key) of a generic attribute; None if unsupported."""
    layout = _ATTRIBUTE_LAYOUT.get(attribute.data_type)
    if layout is None:
        return None
    key, width, dtype = layout
    if attribute.data_type == "BYTE_COLOR" and count and hasattr(attribute.data[0], "color_srgb"):
        key = "color_srgb"  # the stored sRGB bytes, exactly (no linear round trip)
        values = dna_arrays.byte_colors_srgb(attribute) if len(attribute.data) == count else None
        if values is not None:
            return values, key
    return read_array(attribute.data, key, count, width, dtype).reshape(count, width), key


def read_vertex_group(obj: bpy.types.Object, group_index: int, vertex_ids=None):
    """(weights, assigned) of one vertex group for all vertices (or the given ones).

    Blender has no bulk accessor for vertex-group weights, so this walks the vertices'
    group lists once: the only per-vertex loop in the add-on, not on the preview path.
    """
    vertices = obj.data.vertices
    ids = range(len(vertices)) if vertex_ids is None else vertex_ids
    weights = np.zeros(len(ids))
    assigned = np.zeros(len(ids), dtype=bool)
    for i, v in enumerate(ids):
        for g in vertices[v].groups:
            if g.group == group_index:
                weights[i] = g.weight
                assigned[i] = True
                break
    return weights, assigned


def read_vertex_weights(obj, vertex_ids) -> tuple:
    """(group names in index order, SparseWeights of the given vertices: rows are their ids).

    Walks only those vertices (Blender has no bulk accessor for deform weights)."""
    names = [group.name for group in obj.vertex_groups]
    rows, columns, values = [], [], []
    if names:
        vertices = obj.data.vertices
        for v in np.unique(np.asarray(vertex_ids, dtype=np.int64)).tolist():
            for g in vertices[v].groups:
                if g.group < len(names):  # a weight left by a deleted group is not carried
                    rows.append(v)
                    columns.append(g.group)
                    values.append(g.weight)
    return names, SparseWeights(np.asarray(rows, dtype=np.int64), np.asarray(columns, dtype=np.int64),
                                np.asarray(values, dtype=np.float64))


def write_vertex_weights(obj, names: list, weights: SparseWeights) -> None:
    """Writes ``weights`` (rows: ``obj``'s vertices, columns: indices into ``names``) into the
    object's vertex groups, creating every named group that is missing (in ``names``' order)."""
    groups = [obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name) for name in names]
    if len(weights.vertex) == 0:
        return
    value = np.asarray(weights.weight, dtype=np.float32)  # what Blender stores
    column = np.asarray(weights.group, dtype=np.int64)
    order = np.lexsort((value, column))
    vertex, column, value = np.asarray(weights.vertex)[order], column[order], value[order]
    # one bulk call per group and distinct weight
    starts = np.flatnonzero(np.r_[True, (column[1:] != column[:-1]) | (value[1:] != value[:-1])])
    ends = np.r_[starts[1:], len(order)]
    for start, end in zip(starts.tolist(), ends.tolist()):
        groups[column[start]].add(vertex[start:end].tolist(), float(value[start]), "REPLACE")


def collect_vertex_groups(obj, kept: np.ndarray) -> dict:
    """{group name: (output vertex ids, weights)} for the kept vertices of ``obj`` (output
    vertex i is input vertex kept[i])."""
    kept = np.asarray(kept, dtype=np.int64)
    if not len(obj.vertex_groups):
        return {}
    names, weights = read_vertex_weights(obj, kept)
    # every output vertex of each weight's input vertex (kept sorted stably: outputs in order)
    order = np.argsort(kept, kind="stable")
    rows, count = matching_rows(kept[order], weights.vertex)
    output, group, weight = order[rows], np.repeat(weights.group, count), np.repeat(weights.weight, count)
    return {name: (output[group == g].tolist(), weight[group == g].tolist()) for g, name in enumerate(names)}


def apply_vertex_groups(obj, groups: dict) -> None:
    """Writes collected weights into ``obj``'s mesh, creating missing groups by name."""
    names = list(groups)
    vertex = [np.asarray(ids, dtype=np.int64) for ids, _ in groups.values()]
    weight = [np.asarray(values, dtype=np.float64) for _, values in groups.values()]
    column = [np.full(len(ids), g, dtype=np.int64) for g, ids in enumerate(vertex)]
    empty = [np.zeros(0, dtype=np.int64)]
    write_vertex_weights(obj, names, SparseWeights(np.concatenate(vertex + empty), np.concatenate(column + empty),
                                                   np.concatenate(weight + [np.zeros(0)])))
