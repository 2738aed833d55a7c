"""Writing a Blender mesh: a triangle mesh's geometry (the preview's fast path), and a result
mesh that carries over the source's materials, smooth flags, UV maps, colour and generic
attributes, custom split normals (vertices the quality mode moved interpolate theirs) and the
seam and sharp flags of edges along the input's flagged curves (edge_flags).
"""

from __future__ import annotations

from typing import Optional

import bpy
import numpy as np

from ...core.carry.attributes import FLAT_CORNER_ANGLE, MovedVertices, corner_values, moved_vertices, point_values
from ...core.api.mesh_edges import mesh_edges
from ...core.carry.look_fit import fit_look, vertex_means
from .mesh_access import attribute_for_write, domain_size, read_array, write_indices
from .mesh_read import MeshArrays, position_attribute, read_custom_normals, read_polygon_smooth
from .mesh_attributes import INTERPOLATED, SKIPPED_ATTRIBUTES, read_attribute, read_uv_map, write_uv_map
from .edge_flags import calc_edges, carry_edge_flags


def write_positions(mesh, vertices: np.ndarray) -> None:
    """Sets every vertex position of ``mesh`` (as many rows as it has vertices)."""
    if not len(vertices):
        return
    flat = np.ascontiguousarray(vertices, dtype=np.float32).ravel()
    attribute = position_attribute(mesh)
    if attribute is not None:
        attribute.data.foreach_set("vector", flat)
    else:
        mesh.vertices.foreach_set("co", flat)


def write_polygon_materials(mesh, materials: np.ndarray) -> None:
    """Sets every polygon's material slot: the "material_index" attribute in 4.0+, where
    MeshPolygon.material_index goes one polygon at a time."""
    values = np.ascontiguousarray(materials, dtype=np.int32)
    if bpy.app.version >= (4, 0, 0):
        attribute_for_write(mesh, "material_index", "INT", "FACE").data.foreach_set("value", values)
    else:
        mesh.polygons.foreach_set("material_index", values)


def write_polygon_smooth(mesh, smooth: np.ndarray) -> None:
    """Sets the smooth flag of polygons just added to ``mesh``. New polygons are smooth in 4.0+
    (no "sharp_face" attribute) and flat before, so only a change from that default is written:
    in 4.0+ through "sharp_face", as MeshPolygon.use_smooth goes one polygon at a time there (97
    ms for 1.55M in 4.5)."""
    smooth = np.asarray(smooth, dtype=bool)
    if bpy.app.version >= (4, 0, 0):
        if not smooth.all():
            attribute_for_write(mesh, "sharp_face", "BOOLEAN", "FACE").data.foreach_set("value", ~smooth)
    elif smooth.any():
        mesh.polygons.foreach_set("use_smooth", smooth)


def fill_geometry(mesh: bpy.types.Mesh, vertices: np.ndarray, triangles: np.ndarray, edges=None) -> None:
    """Replaces ``mesh``'s geometry by a triangle mesh (no attributes); the fast preview path.

    ``edges`` (a :class:`topstoc.core.MeshEdges` of ``triangles``) is computed here when not
    given; the preview computes it on its worker thread. Writing the edges ourselves replaces
    ``mesh.update(calc_edges=True)``, which was a large part of a preview update.
    Triangles the engine cannot take (a repeated vertex) are left to Blender's edge pass.
    """
    mesh.clear_geometry()
    n, m = len(vertices), len(triangles)
    if m and edges is None:
        try:
            edges = mesh_edges(triangles, n)
        except ValueError:
            pass
    mesh.vertices.add(n)
    mesh.loops.add(3 * m)
    mesh.polygons.add(m)
    write_positions(mesh, vertices)
    if m:
        corners = np.ascontiguousarray(triangles, dtype=np.int32).ravel()
        write_indices(mesh, ".corner_vert", mesh.loops, "vertex_index", corners)
        write_polygon_loops(mesh, np.arange(0, 3 * m, 3), np.full(m, 3))
        if edges is not None:
            mesh.edges.add(len(edges))
            write_indices(mesh, ".edge_verts", mesh.edges, "vertices", edges.vertices)
            write_indices(mesh, ".corner_edge", mesh.loops, "edge_index", edges.corner_edge)
    calc_edges(mesh, m > 0 and edges is None)


def write_polygon_loops(mesh, starts: np.ndarray, totals: np.ndarray) -> None:
    """Every polygon's first loop and loop count (Blender 4.0+ derives the count from the starts)."""
    write_indices(mesh, None, mesh.polygons, "loop_start", starts)
    if bpy.app.version < (4, 0, 0):
        write_indices(mesh, None, mesh.polygons, "loop_total", totals)


def _display_colors(source, out, guidance) -> None:
    """The result's active and render colours: the source's, except that a guidance layer gives
    way to the first other colour attribute (Blender always shows one when any exists)."""
    colors = source.color_attributes
    render = colors[colors.render_color_index] if 0 <= colors.render_color_index < len(colors) else None
    others = [a for a in out.color_attributes if a.name not in guidance]
    for attribute, setter in ((colors.active_color, "active"), (render, "render")):
        chosen = out.color_attributes.get(attribute.name) if attribute is not None else None
        if chosen is None or chosen.name in guidance:
            chosen = others[0] if others else chosen
        if chosen is None:
            continue
        if setter == "active":
            out.color_attributes.active_color = chosen
        else:
            out.color_attributes.render_color_index = list(out.color_attributes).index(chosen)


def flat_corners(source, normals, corner_loop) -> np.ndarray:
    """Which output corners come from a flat-shaded input corner (its custom normal its polygon's,
    within attributes.FLAT_CORNER_ANGLE): they take their output face's normal, so a faceted
    asset stays faceted where the engine merged faces across edges that were not creases."""
    count = len(source.polygons)
    polygon_normals = read_array(source.polygons, "normal", count, 3, np.float64)
    totals = read_array(source.polygons, "loop_total", count, 1, np.int64).ravel()
    starts = read_array(source.polygons, "loop_start", count, 1, np.int64).ravel()
    order = np.argsort(starts, kind="stable")  # a polygon's loops are consecutive, polygons tile the loops
    loop_polygon = np.repeat(order, totals[order])
    cosine = (normals[corner_loop] * polygon_normals[loop_polygon[corner_loop]]).sum(axis=1)
    return cosine >= np.cos(np.radians(FLAT_CORNER_ANGLE))


def face_normals(vertices, triangles) -> np.ndarray:
    """(m, 3) unit normals of triangles (zero for degenerate ones)."""
    p = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def fitted_look(source: bpy.types.Mesh, arrays: MeshArrays, result, look: dict, carried) -> dict:
    """The layers of the look that was in the cost, fitted to the source's (core.carry.look_fit):
    {("uv", name) | ("color", name) | ("normal", None): values on the layer's domain}. ``look``:
    {"uv": the UV map's name, "color": the colour attribute's name, "normal": True}, each
    optional; ``carried(values, domain)`` gives a layer's carried values (build_result_mesh)."""
    triangles = np.asarray(result.triangles, dtype=np.int64)
    layers, domains = {}, {}
    if look.get("uv") and look["uv"] in source.uv_layers:
        values = read_uv_map(source, look["uv"])
        layers[("uv", look["uv"])] = (values[arrays.triangle_loops], carried(values, "CORNER"), "uv")
    attribute = source.attributes.get(look["color"]) if look.get("color") else None
    if attribute is not None and attribute.domain in ("POINT", "CORNER"):
        read = read_attribute(attribute, domain_size(source, attribute.domain))
        if read is not None:
            values = read[0]
            point = attribute.domain == "POINT"
            at = arrays.triangles if point else arrays.triangle_loops
            here = carried(values, attribute.domain)
            layers[("color", look["color"])] = (values[at], here[triangles] if point else here, "color")
            domains[("color", look["color"])] = (attribute.domain, values.dtype)
    normals = read_custom_normals(source) if look.get("normal") else None
    if normals is not None:
        layers[("normal", None)] = (normals[arrays.triangle_loops], carried(normals, "CORNER"), "normal")
    fitted = fit_look(arrays.vertices, arrays.triangles, result.vertices, triangles, layers, result.kept)
    for key, (domain, dtype) in domains.items():
        values = fitted[key]
        if domain == "POINT":
            values = vertex_means(values, triangles, len(result.vertices))
        fitted[key] = np.rint(values).astype(dtype) if np.issubdtype(dtype, np.integer) else values.astype(dtype)
    return fitted


def build_result_mesh(source: bpy.types.Mesh, arrays: MeshArrays, result, name: str,
                      moved: Optional[MovedVertices] = None, guidance: tuple = (), keep_guidance: bool = True,
                      look: Optional[dict] = None) -> bpy.types.Mesh:
    """A new mesh datablock holding ``result`` with the source's attributes carried over.

    ``guidance``: the names of the guidance paint layers. They are never the result's active or
    render colour (an exported LOD would show the paint), and not carried at all unless
    ``keep_guidance`` (an object decimated in place keeps its paint; a new result does not need it).

    Points take the attributes of their kept input vertex, faces those of their source
    polygon, corners those of the input loop ``corner_source`` names. Vertices the quality mode
    moved (``moved``, found when not given) take point and corner values interpolated in their
    source triangle (topstoc.core.carry.attributes; corners from that triangle's own loops, so UV
    seams stay exact); integers, flags and rotations take the nearest corner's value. Output
    edges are new: seam and sharp flags mark the output edges that follow a flagged input curve
    (carry_edge_flags); creases and bevel weights are not carried. ``look`` (the layers that
    were in the cost, fitted_look): those are fitted to the source's look after the carry.
    """
    out = bpy.data.meshes.new(name)
    fill_geometry(out, result.vertices, result.triangles)
    kept = np.asarray(result.kept, dtype=np.int64)
    face_polygon = arrays.polygons_of(result.face_source)
    corner_loop = arrays.loops_of(result.corner_source)
    m = len(result.triangles)
    if moved is None:
        moved = moved_vertices(arrays.vertices, arrays.triangles, result)

    def carried(values, domain: str, nearest: bool = False) -> np.ndarray:
        """Source values of one domain for the output's elements of that domain."""
        if domain == "POINT":
            return point_values(values, kept, moved, arrays.triangles, nearest)
        if domain == "CORNER":
            return corner_values(values, corner_loop, result.triangles, moved, arrays.loop_map, nearest)
        return values[face_polygon]

    fitted = fitted_look(source, arrays, result, look, carried) if look and m else {}
    for material in source.materials:
        out.materials.append(material)
    if m and np.any(arrays.polygon_material):  # all zero is Blender's default: no write
        write_polygon_materials(out, arrays.polygon_material[face_polygon])
    smooth = read_polygon_smooth(source) if m else None
    if smooth is not None:
        write_polygon_smooth(out, smooth[face_polygon])

    uv_names = set()
    for uv in source.uv_layers:
        uv_names.add(uv.name)
        if ("uv", uv.name) in fitted:
            write_uv_map(out, uv.name, fitted[("uv", uv.name)])
            continue
        write_uv_map(out, uv.name, carried(read_uv_map(source, uv.name), "CORNER") if m else np.zeros((0, 2)))
    if source.uv_layers.active is not None:
        out.uv_layers.active_index = source.uv_layers.active_index

    for attribute in source.attributes:
        name_ = attribute.name
        if (name_.startswith(".") or name_ in SKIPPED_ATTRIBUTES or name_ in uv_names
                or attribute.domain not in ("POINT", "FACE", "CORNER") or (name_ in guidance and not keep_guidance)):
            continue
        count = domain_size(source, attribute.domain)
        read = read_attribute(attribute, count)
        if read is None:
            continue
        values, key = read
        target = attribute_for_write(out, name_, attribute.data_type, attribute.domain)
        picked = fitted.get(("color", name_))
        if picked is None:
            picked = carried(values, attribute.domain, nearest=attribute.data_type not in INTERPOLATED)
        if len(picked):
            target.data.foreach_set(key, np.ascontiguousarray(picked).ravel())
    _display_colors(source, out, guidance)
    carry_edge_flags(source, out, kept, moved.face >= 0)

    normals = read_custom_normals(source)
    if normals is not None and m:
        if hasattr(out, "use_auto_smooth"):  # Blender < 4.1 needs auto smooth for custom normals
            out.use_auto_smooth = True
            out.auto_smooth_angle = source.auto_smooth_angle
        corner_normals = fitted.get(("normal", None))  # fitted ones are unit already
        if corner_normals is None:
            corner_normals = carried(normals, "CORNER")
        mixed = moved.face[np.asarray(result.triangles).ravel()] >= 0  # interpolated: unit length again
        length = np.linalg.norm(corner_normals[mixed], axis=1, keepdims=True)
        corner_normals[mixed] = corner_normals[mixed] / np.where(length > 0, length, 1)
        flat = flat_corners(source, normals, corner_loop)
        corner_normals[flat] = np.repeat(face_normals(result.vertices, result.triangles), 3, axis=0)[flat]
        out.normals_split_custom_set(corner_normals)
    out.update()
    return out
