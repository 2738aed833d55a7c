"""Writes a topology edit (topstoc.core.api.edit.EditResult) back into a Blender mesh.

The engine edits the mesh's loop triangles; this module turns the result back into polygons:

- a polygon all of whose triangles survived, each corner mapping to one vertex, stays the same
  polygon (quads and n-gons stay quads and n-gons, with their corner data);
- a polygon the edit split (a cut along one of its diagonals) or partly deleted keeps its
  surviving triangles as triangles, with the polygon's face data and their corners' data;
- patch triangles (filled holes) are new triangles: face data from a face next to the hole,
  corner data from the neighbouring corner at old vertices (so UVs continue), the patch's mean
  at vertices the patch created; those vertices take the mean of the hole's border.

Point, face, corner and edge attributes, UV maps, materials, smooth flags, selection and hiding,
vertex groups and custom split normals carry over; edges are matched by their source vertices,
so seams, sharp edges and creases survive. Meshes with shape keys are refused (clear message):
rebuilding them is not supported.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

from ...core.support.errors import TopStocError
from ...core.support.ranges import concatenated_ranges
from . import mesh_access, mesh_read, mesh_write, mesh_attributes, edge_flags

# Per-element properties read and written through foreach_get/set where the Blender version has them.
_VERTEX_FLAGS = ("select", "hide")
_EDGE_FLAGS = ("select", "hide", "use_seam", "use_edge_sharp", "use_freestyle_mark", "crease", "bevel_weight")
_POLYGON_FLAGS = ("select", "hide", "use_freestyle_mark")
_SKIPPED = {"position", "material_index", "sharp_face", "normal"}


class EditError(TopStocError):
    """An edit that cannot be written (message for the status bar)."""


@dataclass
class PolygonLayout:
    """The edited mesh as polygons, with the source of every element."""

    vertices: np.ndarray        #: (n, 3) positions
    vertex_source: np.ndarray   #: (n,) input vertex or -1
    loop_start: np.ndarray      #: (p,) first corner of each polygon
    loop_total: np.ndarray      #: (p,) corners per polygon
    corner_vertex: np.ndarray   #: (c,) vertex of each corner
    corner_loop: np.ndarray     #: (c,) input loop whose data the corner takes, or -1
    polygon_source: np.ndarray  #: (p,) input polygon whose data the polygon takes, or -1
    corner_patch: np.ndarray    #: (c,) index of the patch a corner belongs to, or -1


def polygon_layout(arrays: mesh_read.MeshArrays, result) -> PolygonLayout:
    """Maps an EditResult on ``arrays``' loop triangles back to polygons (see the module text)."""
    triangle_loops = arrays.triangle_loops
    n_loops = arrays.num_loops
    face_source = np.asarray(result.face_source, dtype=np.int64)
    corner_source = np.asarray(result.corner_source, dtype=np.int64).reshape(-1, 3)
    out_triangles = np.asarray(result.triangles, dtype=np.int64).reshape(-1, 3)
    from_input = face_source >= 0

    # Which new vertex every input loop became; a loop seen with two different vertices was split.
    rows = np.flatnonzero(from_input)
    corner_in = corner_source[rows].reshape(-1)
    loops = triangle_loops.reshape(-1)[corner_in]
    new_vertex = out_triangles[rows].reshape(-1)
    first = np.full(n_loops, -1, dtype=np.int64)
    last = np.full(n_loops, -1, dtype=np.int64)
    first[loops[::-1]] = new_vertex[::-1]
    last[loops] = new_vertex
    split_loop = first != last

    polygons = len(arrays.polygon_material)
    triangle_alive = np.zeros(len(arrays.triangles), dtype=bool)
    triangle_alive[face_source[rows]] = True
    dead = np.bincount(arrays.triangle_polygon, weights=~triangle_alive, minlength=polygons)
    split = np.bincount(arrays.triangle_polygon, weights=split_loop[triangle_loops].any(axis=1), minlength=polygons)
    intact = (dead == 0) & (split == 0)
    triangles_of = np.bincount(arrays.triangle_polygon, minlength=polygons)
    intact &= triangles_of > 0

    # Intact polygons keep their corners (in their order).
    starts, totals = _polygon_corners(arrays, polygons)
    keep = np.flatnonzero(intact)
    keep_totals = totals[keep]
    keep_loops = concatenated_ranges(starts[keep], keep_totals)
    # Triangles of broken polygons and patch triangles become triangle polygons.
    broken_rows = rows[~intact[arrays.triangle_polygon[face_source[rows]]]]
    patch_rows = np.flatnonzero(~from_input)
    tri_rows = np.concatenate([broken_rows, patch_rows])
    tri_corner_source = corner_source[tri_rows].reshape(-1)
    tri_corner_loop = np.where(tri_corner_source >= 0,
                               triangle_loops.reshape(-1)[np.maximum(tri_corner_source, 0)], -1)
    # face data of a patch triangle: the polygon of a triangle next to the hole
    next_to = corner_source[patch_rows].max(axis=1) // 3 if len(patch_rows) else np.zeros(0, dtype=np.int64)
    patch_polygon = np.where(next_to >= 0, arrays.triangle_polygon[np.maximum(next_to, 0)], -1)
    tri_polygon = np.concatenate([arrays.triangle_polygon[face_source[broken_rows]], patch_polygon])

    loop_total = np.concatenate([keep_totals, np.full(len(tri_rows), 3)]).astype(np.int64)
    loop_start = np.concatenate([[0], np.cumsum(loop_total)[:-1]]).astype(np.int64) if len(loop_total) \
        else np.zeros(0, dtype=np.int64)
    corner_vertex = np.concatenate([first[keep_loops], out_triangles[tri_rows].reshape(-1)])
    corner_loop = np.concatenate([keep_loops, tri_corner_loop])
    patch_of_row = np.full(len(face_source), -1, dtype=np.int64)
    for index, patch in enumerate(result.patches):
        patch_of_row[patch.triangles] = index
    corner_patch = np.concatenate([np.full(len(keep_loops), -1), np.repeat(patch_of_row[tri_rows], 3)])
    return PolygonLayout(
        vertices=np.asarray(result.vertices, dtype=np.float64), vertex_source=np.asarray(result.vertex_source),
        loop_start=loop_start, loop_total=loop_total, corner_vertex=corner_vertex.astype(np.int64),
        corner_loop=corner_loop.astype(np.int64), polygon_source=np.concatenate([keep, tri_polygon]).astype(np.int64),
        corner_patch=corner_patch)


def _polygon_corners(arrays, polygons: int):
    """(loop_start, loop_total) per polygon, from the triangles' loops (polygons are fans). The
    triangles are grouped by polygon (Blender lists a polygon's loop triangles together, in
    polygon order: then no sort is needed) and each group's smallest and largest loop taken."""
    triangle_polygon = np.asarray(arrays.triangle_polygon, dtype=np.int64)
    order = None if np.all(triangle_polygon[1:] >= triangle_polygon[:-1]) else \
        np.argsort(triangle_polygon, kind="stable")
    grouped = triangle_polygon if order is None else triangle_polygon[order]
    loops = arrays.triangle_loops if order is None else arrays.triangle_loops[order]
    starts = np.full(polygons, np.iinfo(np.int64).max, dtype=np.int64)
    ends = np.full(polygons, -1, dtype=np.int64)
    if len(grouped):
        first = np.flatnonzero(np.r_[True, grouped[1:] != grouped[:-1]])
        starts[grouped[first]] = np.minimum.reduceat(loops.min(axis=1), first)
        ends[grouped[first]] = np.maximum.reduceat(loops.max(axis=1), first)
    return starts, ends - starts + 1


def _fill_polygons(mesh, layout: PolygonLayout, loose_edges: np.ndarray) -> None:
    mesh.vertices.add(len(layout.vertices))
    mesh_write.write_positions(mesh, layout.vertices)
    if len(loose_edges):
        mesh.edges.add(len(loose_edges))
        mesh_access.write_indices(mesh, ".edge_verts", mesh.edges, "vertices", loose_edges)
    corners = len(layout.corner_vertex)
    mesh.loops.add(corners)
    mesh.polygons.add(len(layout.loop_total))
    if corners:
        mesh_access.write_indices(mesh, ".corner_vert", mesh.loops, "vertex_index", layout.corner_vertex)
        mesh_write.write_polygon_loops(mesh, layout.loop_start, layout.loop_total)
    edge_flags.calc_edges(mesh)


def _gather(values: np.ndarray, source: np.ndarray) -> np.ndarray:
    out = np.zeros((len(source),) + values.shape[1:], dtype=values.dtype)
    valid = source >= 0
    out[valid] = values[source[valid]]
    return out


def _patch_mean(values: np.ndarray, source: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Rows without a source take the mean of their group's rows that have one."""
    out = _gather(values, source)
    for group in np.unique(groups[(source < 0) & (groups >= 0)]):
        members = groups == group
        known = members & (source >= 0)
        if known.any():
            out[members & (source < 0)] = out[known].mean(axis=0).astype(out.dtype)
    return out


def _vertex_values(values: np.ndarray, layout: PolygonLayout, result) -> np.ndarray:
    """Per-vertex data for the new vertices: copies, or the mean of the patch's border."""
    out = _gather(values, layout.vertex_source)
    for patch in result.patches:
        created = np.arange(patch.vertices.start, patch.vertices.stop)
        if len(created):
            sources = layout.vertex_source[np.asarray(patch.boundary)]
            sources = sources[sources >= 0]
            if len(sources):
                out[created] = values[sources].mean(axis=0).astype(values.dtype)
    return out


def _edge_keys(edges: np.ndarray, n: int) -> np.ndarray:
    a, b = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64), np.maximum(edges[:, 0], edges[:, 1]).astype(np.int64)
    return a * n + b


def _edge_sources(old_mesh, new_mesh, vertex_source: np.ndarray) -> np.ndarray:
    """For each new edge, the old edge between the same source vertices, or -1."""
    n_old = len(old_mesh.vertices)
    old_edges = mesh_access.read_indices(old_mesh.edges, "vertices", len(old_mesh.edges), 2).astype(np.int64)
    new_edges = mesh_access.read_indices(new_mesh.edges, "vertices", len(new_mesh.edges), 2).astype(np.int64)
    if len(new_edges) == 0 or len(old_edges) == 0:
        return np.full(len(new_edges), -1, dtype=np.int64)
    ends = vertex_source[new_edges]
    valid = (ends >= 0).all(axis=1)
    keys = np.full(len(new_edges), -1, dtype=np.int64)
    keys[valid] = _edge_keys(ends[valid], n_old)
    old_keys = _edge_keys(old_edges, n_old)
    order = np.argsort(old_keys)
    sorted_keys = old_keys[order]
    # searched in key order: a sorted search walks the sorted keys forward (3x faster on 2.3M)
    asked = np.argsort(keys)
    position = np.empty(len(keys), dtype=np.int64)
    position[asked] = np.searchsorted(sorted_keys, keys[asked])
    position = np.minimum(position, len(order) - 1)
    found = valid & (sorted_keys[position] == keys)
    return np.where(found, order[position], -1)


def _copy_flags(old, new, domain: str, names, source: np.ndarray, unreadable=()) -> None:
    """Element flags of ``old``'s elements of ``domain`` onto ``new``'s (each from its source
    element, unflagged without one)."""
    collection_old = getattr(old, mesh_access.DOMAIN_COLLECTIONS[domain])
    collection_new = getattr(new, mesh_access.DOMAIN_COLLECTIONS[domain])
    if len(collection_new) == 0 or len(collection_old) == 0:
        return
    names = [name for name in names if name not in unreadable]
    as_attributes = edge_flags.ELEMENT_FLAG_ATTRIBUTES[domain] if bpy.app.version >= (4, 0, 0) else {}
    _copy_flag_attributes(old, new, domain, [name for name in names if name in as_attributes], source)
    element = collection_old[0]
    for name in names:
        if name in as_attributes or not hasattr(element, name):
            continue
        dtype = bool if isinstance(getattr(element, name), bool) else np.float32
        picked = _gather(mesh_access.read_array(collection_old, name, len(collection_old), 1, dtype), source)
        if picked.any():
            collection_new.foreach_set(name, picked)


def _copy_flag_attributes(old, new, domain: str, names, source: np.ndarray) -> None:
    """Blender 4.0+: flags are attributes, present only when some element has the flag."""
    for name in names:
        attribute = edge_flags.element_flag_attribute(old, domain, name)
        kind = edge_flags.ELEMENT_FLAG_ATTRIBUTES[domain][name][1]
        if attribute is None or (attribute.domain, attribute.data_type) != (domain, kind):
            continue  # none flagged (the default), or mistyped (see edge_flags.mistyped_edge_flags)
        values, key = mesh_attributes.read_attribute(attribute, mesh_access.domain_size(old, domain))
        picked = _gather(values[:, 0], source)
        if picked.any():
            mesh_access.attribute_for_write(new, attribute.name, kind, domain).data.foreach_set(key, picked)


def _copy_attributes(old, new, layout: PolygonLayout, result, edge_source: np.ndarray, uv_names: set) -> None:
    sources = {"POINT": layout.vertex_source, "FACE": layout.polygon_source, "EDGE": edge_source,
               "CORNER": layout.corner_loop}
    # flags (4.0+: attributes such as "sharp_edge" too) go through _copy_flags
    flag_names = {name for flags in edge_flags.ELEMENT_FLAG_ATTRIBUTES.values() for names, _ in flags.values()
                  for name in names} if bpy.app.version >= (4, 0, 0) else set()
    for attribute in old.attributes:
        name = attribute.name
        # internal ("." names: selection, hiding, topology) go through the element flags above
        if name in _SKIPPED or name.startswith(".") or name in uv_names or attribute.domain not in sources \
                or name in flag_names:
            continue
        read = mesh_attributes.read_attribute(attribute, mesh_access.domain_size(old, attribute.domain))
        if read is None:
            continue
        values, key = read
        domain = attribute.domain
        if domain == "POINT":
            picked = _vertex_values(values, layout, result)
        elif domain == "CORNER":
            picked = _patch_mean(values, layout.corner_loop, layout.corner_patch)
        else:
            picked = _gather(values, sources[domain])
        target = mesh_access.attribute_for_write(new, name, attribute.data_type, domain)
        if len(picked):
            target.data.foreach_set(key, np.ascontiguousarray(picked).ravel())


def build_edited_mesh(old, arrays: mesh_read.MeshArrays, result, new) -> bpy.types.Mesh:
    """Fills the empty mesh ``new`` with ``result`` (an EditResult on ``arrays``, read from the
    mesh ``old``) and ``old``'s attributes."""
    layout = polygon_layout(arrays, result)
    vertex_map = np.full(len(old.vertices), -1, dtype=np.int64)
    created = np.flatnonzero(layout.vertex_source >= 0)
    vertex_map[layout.vertex_source[created][::-1]] = created[::-1]
    from ..analysis.topology import loose_edges

    wires = loose_edges(old)
    wires = vertex_map[wires] if len(wires) else np.zeros((0, 2), dtype=np.int64)
    wires = wires[(wires >= 0).all(axis=1)] if len(wires) else wires
    _fill_polygons(new, layout, wires)

    if len(new.materials) == 0:
        for material in old.materials:
            new.materials.append(material)
    polygon_source = layout.polygon_source
    if len(polygon_source) and np.any(arrays.polygon_material):
        mesh_write.write_polygon_materials(new, _gather(arrays.polygon_material, polygon_source))
    smooth = mesh_read.read_polygon_smooth(old) if len(polygon_source) else None
    if smooth is not None:
        mesh_write.write_polygon_smooth(new, _gather(smooth, polygon_source))

    uv_names = set()
    for uv in old.uv_layers:
        uv_names.add(uv.name)
        values = mesh_attributes.read_uv_map(old, uv.name)
        mesh_attributes.write_uv_map(new, uv.name, _patch_mean(values, layout.corner_loop, layout.corner_patch)
                             if len(layout.corner_loop) else values[:0])
    if old.uv_layers.active is not None:
        new.uv_layers.active_index = old.uv_layers.active_index

    edge_source = _edge_sources(old, new, layout.vertex_source)
    _copy_flags(old, new, "POINT", _VERTEX_FLAGS, layout.vertex_source)
    _copy_flags(old, new, "EDGE", _EDGE_FLAGS, edge_source, unreadable=edge_flags.mistyped_edge_flags(old))
    _copy_flags(old, new, "FACE", _POLYGON_FLAGS, polygon_source)
    _copy_attributes(old, new, layout, result, edge_source, uv_names)
    colors = old.color_attributes
    if colors.active_color is not None and new.color_attributes.get(colors.active_color.name) is not None:
        new.color_attributes.active_color = new.color_attributes[colors.active_color.name]

    normals = mesh_read.read_custom_normals(old)
    if normals is not None and len(layout.corner_loop):
        if hasattr(new, "use_auto_smooth"):
            new.use_auto_smooth = True
            new.auto_smooth_angle = old.auto_smooth_angle
        new.normals_split_custom_set(_patch_mean(normals, layout.corner_loop, layout.corner_patch))
    new.update()
    return new


def apply_edit(obj, arrays: mesh_read.MeshArrays, result) -> bpy.types.Mesh:
    """Writes the edit into ``obj``'s own mesh datablock (so Edit Mode, undo, other users of the
    mesh and its settings see the same datablock); vertex groups follow the vertices."""
    mesh = obj.data
    if mesh.shape_keys is not None:
        raise EditError(f"'{obj.name}' has shape keys; apply or remove them before editing its topology")
    source = np.asarray(result.vertex_source, dtype=np.int64)
    copies = np.flatnonzero(source >= 0)
    groups = mesh_attributes.collect_vertex_groups(obj, source[copies])
    snapshot = mesh.copy()  # the data to carry over, read while the mesh itself is rebuilt
    try:
        mesh.clear_geometry()
        build_edited_mesh(snapshot, arrays, result, mesh)
    finally:
        bpy.data.meshes.remove(snapshot)
    for group_name, (ids, weights) in groups.items():
        groups[group_name] = (copies[np.asarray(ids, dtype=np.int64)].tolist(), weights)
    mesh_attributes.apply_vertex_groups(obj, groups)
    return mesh
