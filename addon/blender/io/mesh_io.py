"""Blender mesh <-> numpy arrays (foreach_get / foreach_set only, no per-element loops).

Reading triangulates n-gons through Blender's loop triangles and keeps, for every triangle,
its polygon and the loop of each corner, so results can take every attribute exactly from
the face and corner they came from. Writing builds a triangle mesh from a DecimateResult and
copies UV maps, colour and generic attributes, materials, smooth flags, custom split normals
(vertices the quality mode moved interpolate theirs) and the seam and sharp flags of edges along
the input's flagged curves (core/carry/edge_flags.py); vertex-group weights are read and written
sparsely (read_vertex_weights, write_vertex_weights).

Where Blender keeps a field as a plain attribute (positions and UV maps from 3.5, material slots
and flat shading from 4.0), it is read and written through that attribute: its foreach_get/set
copy the array at once, while MeshVertex.co, MeshUVLoop.uv and the like go one element at a time
(30 to 100 times slower in 4.5 and 5.0). Blender 3.x's edge, loop and polygon structs are read
through dna_arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import bpy
import numpy as np

from ...core.carry.attributes import (FLAT_CORNER_ANGLE, MovedVertices, SparseWeights, corner_values, moved_vertices,
                                      point_values)
from ...core.support.digest import array_digest
from ...core.carry.edge_flags import carried_edge_flags
from ...core.support import fresh_memory
from ...core.api.mesh_edges import mesh_edges
from ...core.support.ranges import matching_rows
from . import dna_arrays

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
_SKIPPED_ATTRIBUTES = {"position", "material_index", "sharp_face", "sharp_edge", "normal"}
# Attribute types whose values a moved vertex interpolates (the others take the nearest corner's).
_INTERPOLATED = {"FLOAT", "FLOAT2", "FLOAT_VECTOR", "FLOAT_COLOR", "BYTE_COLOR"}


@dataclass
class MeshArrays:
    """A Blender mesh as the engine sees it (object-local coordinates).

    For a mesh of triangles stored in loop order (Blender's usual layout) the triangles are the
    polygons and their corners the loops in order: ``triangle_polygon`` and ``triangle_loops``
    are then made when first read (``None`` given), since the Live Preview's start, which reads
    the mesh on the main thread, rarely needs them (two arrays of 4 and 12 bytes a triangle)."""

    vertices: np.ndarray          #: (n, 3) float64
    triangles: np.ndarray         #: (m, 3) int32 vertex ids (loop triangles)
    _triangle_polygon: Optional[np.ndarray]  #: (m,) int32 polygon of each triangle
    _triangle_loops: Optional[np.ndarray]    #: (m, 3) int32 loop of each triangle corner
    polygon_material: np.ndarray  #: (p,) int32 material slot per polygon
    num_edges: int
    num_loops: int

    @property
    def triangle_polygon(self) -> np.ndarray:
        if self._triangle_polygon is None:
            self._triangle_polygon = np.arange(len(self.triangles), dtype=np.int32)
        return self._triangle_polygon

    @property
    def triangle_loops(self) -> np.ndarray:
        if self._triangle_loops is None:
            self._triangle_loops = np.arange(3 * len(self.triangles), dtype=np.int32).reshape(-1, 3)
        return self._triangle_loops

    @property
    def triangle_material(self) -> np.ndarray:
        return self.polygon_material[self.triangle_polygon]

    def digest(self) -> str:
        """Fingerprint of the geometry the engine uses (positions and triangles)."""
        return array_digest(self.vertices, self.triangles)


def _get(collection, key: str, count: int, width: int, dtype) -> np.ndarray:
    buffer = fresh_memory.empty(count * width, dtype)
    if count:
        collection.foreach_get(key, buffer)
    return buffer.reshape(count, width) if width > 1 else buffer


def _indices(collection, key: str, count: int, width: int = 1) -> np.ndarray:
    """An index property as int32. Blender keeps many index fields as unsigned ints: a uint32
    buffer takes foreach_get's raw-copy path there (about 10x faster than int32 on 3.4)."""
    return _get(collection, key, count, width, np.uint32).view(np.int32)


def check_mesh_object(obj, error: type) -> None:
    """Raises ``error`` (a TopStocError) unless ``obj`` is a mesh object whose data can be read
    (not in Edit Mode, where the mesh datablock lags behind the edit mesh)."""
    if obj is None or obj.type != "MESH":
        raise error(f"'{getattr(obj, 'name', obj)}' is not a mesh object")
    if obj.mode == "EDIT":
        raise error(f"'{obj.name}' is in Edit Mode; switch to Object Mode")


def _typed_attribute(mesh, name: str, domain: str, data_type: str):
    """``mesh``'s attribute ``name`` when it has that domain and type, else None."""
    attribute = mesh.attributes.get(name)
    if attribute is not None and (attribute.domain, attribute.data_type) == (domain, data_type):
        return attribute
    return None


def attribute_for_write(mesh, name: str, data_type: str, domain: str):
    """``mesh``'s attribute ``name`` of that type and domain: the one it has, or made now (one of
    that name with another type or domain is replaced). Making an attribute invalidates Python
    references to the mesh's other attributes."""
    attribute = mesh.attributes.get(name)
    if attribute is not None and (attribute.domain, attribute.data_type) != (domain, data_type):
        mesh.attributes.remove(attribute)
        attribute = None
    return attribute if attribute is not None else mesh.attributes.new(name, data_type, domain)


def _position_attribute(mesh):
    """The "position" attribute where Blender keeps positions as a plain float3 array (3.5+).
    Its foreach_get/set copy the array at once; MeshVertex.co goes through RNA one vertex at a time
    there, tens of times slower."""
    if bpy.app.version < (3, 5, 0):  # positions live in MVert; a layer of that name is the user's
        return None
    return _typed_attribute(mesh, "position", "POINT", "FLOAT_VECTOR")


def read_positions(mesh) -> np.ndarray:
    """(n, 3) float32 vertex positions (object-local)."""
    attribute = _position_attribute(mesh)
    return _get(attribute.data if attribute is not None else mesh.vertices,
                "vector" if attribute is not None else "co", len(mesh.vertices), 3, np.float32)


def write_positions(mesh, vertices: np.ndarray) -> None:
    """Sets every vertex position of ``mesh`` (as many rows as it has vertices)."""
    if not len(vertices):
        return
    flat = np.ascontiguousarray(vertices, dtype=np.float32).ravel()
    attribute = _position_attribute(mesh)
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


def read_polygon_smooth(mesh) -> Optional[np.ndarray]:
    """Every polygon's smooth flag, or None when all are smooth (Blender 4.0+ without a
    "sharp_face" attribute)."""
    sharp = _typed_attribute(mesh, "sharp_face", "FACE", "BOOLEAN")
    if sharp is not None:
        return ~_get(sharp.data, "value", len(mesh.polygons), 1, bool)
    if bpy.app.version >= (4, 0, 0):
        return None
    return _get(mesh.polygons, "use_smooth", len(mesh.polygons), 1, bool)


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


def corner_vertices(mesh) -> np.ndarray:
    """Vertex of every loop (face corner)."""
    return _corner_indices(mesh, ".corner_vert", "v", "vertex_index")


def corner_edges(mesh) -> np.ndarray:
    """Edge of every loop (face corner)."""
    return _corner_indices(mesh, ".corner_edge", "e", "edge_index")


def _corner_indices(mesh, attribute: str, dna_field: str, key: str) -> np.ndarray:
    """A loop index field: the internal attribute (3.6+: a plain int array), or MLoop's field
    copied in one pass (3.x), or MeshLoop's property loop by loop."""
    layer = mesh.attributes.get(attribute)
    if layer is not None:
        return _get(layer.data, "value", len(mesh.loops), 1, np.int32)
    legacy = dna_arrays.loop_indices(mesh, dna_field)
    return legacy if legacy is not None else _indices(mesh.loops, key, len(mesh.loops))


def _triangle_polygons(mesh, count: int) -> np.ndarray:
    if hasattr(mesh, "loop_triangle_polygons"):  # Blender 4.0+
        return _get(mesh.loop_triangle_polygons, "value", count, 1, np.int32)
    return _indices(mesh.loop_triangles, "polygon_index", count)


def _polygon_materials(mesh) -> np.ndarray:
    p = len(mesh.polygons)
    attribute = mesh.attributes.get("material_index")
    if attribute is not None and attribute.domain == "FACE":
        return _get(attribute.data, "value", p, 1, np.int32)
    if len(mesh.materials) <= 1:
        return np.zeros(p, dtype=np.int32)
    return _get(mesh.polygons, "material_index", p, 1, np.int32)


def _triangles_in_loop_order(mesh) -> bool:
    """True when every polygon is a triangle whose loops follow the previous polygon's (how
    Blender stores meshes). Blender triangulates such a polygon into itself, corners in loop
    order, so its loop triangles need not be read one by one."""
    p = len(mesh.polygons)
    if len(mesh.loops) != 3 * p:  # every polygon has 3 loops or more: all are triangles exactly then
        return False
    in_order = dna_arrays.triangles_in_loop_order(mesh)
    return in_order if in_order is not None else dna_arrays.every_third(_indices(mesh.polygons, "loop_start", p))


def read_mesh(mesh: bpy.types.Mesh) -> MeshArrays:
    """Reads positions and the loop triangulation of ``mesh`` (object mode data)."""
    n = len(mesh.vertices)
    vertices = fresh_memory.empty(3 * n, np.float64).reshape(n, 3)
    np.copyto(vertices, read_positions(mesh))
    corners = corner_vertices(mesh)
    if _triangles_in_loop_order(mesh):  # a triangle mesh: the loop triangles are the polygons
        m = len(mesh.polygons)
        triangle_loops = triangle_polygons = None  # in order: made when read (MeshArrays)
        triangles = corners.reshape(m, 3)
    else:
        mesh.calc_loop_triangles()
        m = len(mesh.loop_triangles)
        triangle_loops = _indices(mesh.loop_triangles, "loops", m, 3)
        triangle_polygons = _triangle_polygons(mesh, m)
        triangles = corners[triangle_loops]
    return MeshArrays(vertices, triangles, triangle_polygons, triangle_loops,
                      _polygon_materials(mesh), num_edges=len(mesh.edges), num_loops=len(mesh.loops))


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
        flags = _get(attribute.data, "value", count, 1, bool)
    else:
        pairs = dna_arrays.flagged_edges(mesh, flag)
        if pairs is not None:
            return pairs
        flags = _get(mesh.edges, flag, count, 1, bool)
    if not flags.any():
        return np.zeros((0, 2), dtype=np.int32)
    edges = _get(mesh.edges, "vertices", count, 2, np.int32)
    return edges[flags]


def _uv_attribute(mesh, name: str):
    """The float2 corner attribute Blender 3.5+ keeps a UV map in, whose foreach_get/set copy it
    at once (MeshUVLoop.uv goes one corner at a time in 4.5, tens of times slower); None before
    3.5."""
    if bpy.app.version < (3, 5, 0):
        return None
    return _typed_attribute(mesh, name, "CORNER", "FLOAT2")


def read_uv_maps(mesh: bpy.types.Mesh) -> dict:
    """{name: (num_loops, 2) float32} for every UV map."""
    return {uv.name: read_uv_map(mesh, uv.name) for uv in mesh.uv_layers}


def read_uv_map(mesh: bpy.types.Mesh, name: str) -> np.ndarray:
    """(num_loops, 2) float32 UVs of one UV map."""
    attribute = _uv_attribute(mesh, name)
    if attribute is not None:
        return _get(attribute.data, "vector", len(mesh.loops), 2, np.float32)
    return _get(mesh.uv_layers[name].data, "uv", len(mesh.loops), 2, np.float32)


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
    return _get(attribute.data, key, count, width, dtype).reshape(count, width), key


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


# The mesh collection holding each attribute domain's elements.
DOMAIN_COLLECTIONS = {"POINT": "vertices", "EDGE": "edges", "FACE": "polygons", "CORNER": "loops"}


def _domain_size(mesh, domain: str) -> int:
    return len(getattr(mesh, DOMAIN_COLLECTIONS[domain])) if domain in DOMAIN_COLLECTIONS else -1


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
        _set_int_field(mesh, ".corner_vert", mesh.loops, "vertex_index", corners)
        write_polygon_loops(mesh, np.arange(0, 3 * m, 3), np.full(m, 3))
        if edges is not None:
            mesh.edges.add(len(edges))
            _set_int_field(mesh, ".edge_verts", mesh.edges, "vertices", edges.vertices)
            _set_int_field(mesh, ".corner_edge", mesh.loops, "edge_index", edges.corner_edge)
    calc_edges(mesh, m > 0 and edges is None)


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
        return _get(collection, flag, len(collection), 1, bool)
    attribute = element_flag_attribute(mesh, domain, flag)
    if attribute is None or (attribute.domain, attribute.data_type) != (domain, "BOOLEAN"):
        return np.zeros(len(collection), dtype=bool)  # none flagged, or mistyped (mistyped_edge_flags)
    return _get(attribute.data, "value", len(collection), 1, bool)


def element_flag_attribute(mesh: bpy.types.Mesh, domain: str, flag: str):
    """The attribute that holds ``flag`` (one of ELEMENT_FLAG_ATTRIBUTES) of ``domain``'s elements
    in Blender 4.0+, None when there is none: no element has the flag."""
    return _first_attribute(mesh, ELEMENT_FLAG_ATTRIBUTES[domain][flag][0])


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
        edges = _get(out.edges, "vertices", len(out.edges), 2, np.int32)
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
    return _first_attribute(mesh, _EDGE_FLAG_ATTRIBUTES[flag][0])


def _first_attribute(mesh: bpy.types.Mesh, names):
    """The first of ``names`` that ``mesh`` has as an attribute, or None."""
    for name in names:
        attribute = mesh.attributes.get(name)
        if attribute is not None:
            return attribute
    return None


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


def _set_int_field(mesh, attribute: Optional[str], collection, key: str, values: np.ndarray) -> None:
    """Writes an index field: the internal attribute where Blender has one (``attribute``, 3.6+ /
    4.0+: a plain int array; None where no version has one), else the 3.x struct field in one
    pass (dna_arrays.write_field, about a third faster for a preview frame's geometry), else
    through a uint32 buffer (foreach_set, which 3.x copies field by field)."""
    flat = np.ascontiguousarray(values, dtype=np.int32).ravel()
    layer = mesh.attributes.get(attribute) if attribute else None
    if layer is not None:
        layer.data.foreach_set("value", flat)
    elif not dna_arrays.write_field(collection, key, flat):
        collection.foreach_set(key, flat.view(np.uint32))


def write_polygon_loops(mesh, starts: np.ndarray, totals: np.ndarray) -> None:
    """Every polygon's first loop and loop count (Blender 4.0+ derives the count from the starts)."""
    _set_int_field(mesh, None, mesh.polygons, "loop_start", starts)
    if bpy.app.version < (4, 0, 0):
        _set_int_field(mesh, None, mesh.polygons, "loop_total", totals)


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


def read_custom_normals(mesh) -> Optional[np.ndarray]:
    """(num_loops, 3) float32 custom split normals per corner, or None when the mesh shows none:
    it has no custom normals, or (Blender < 4.1) auto smooth is off, so they are not used."""
    if not mesh.has_custom_normals:
        return None
    if hasattr(mesh, "corner_normals"):  # Blender 4.1+: custom normals are corner normals
        return _get(mesh.corner_normals, "vector", len(mesh.loops), 3, np.float32)
    if not mesh.use_auto_smooth:  # Blender < 4.1 ignores custom normals without auto smooth
        return None
    mesh.calc_normals_split()
    return _get(mesh.loops, "normal", len(mesh.loops), 3, np.float32)


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
    polygon_normals = _get(source.polygons, "normal", count, 3, np.float64)
    totals = _get(source.polygons, "loop_total", count, 1, np.int64).ravel()
    starts = _get(source.polygons, "loop_start", count, 1, np.int64).ravel()
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


def build_result_mesh(source: bpy.types.Mesh, arrays: MeshArrays, result, name: str,
                      moved: Optional[MovedVertices] = None, guidance: tuple = (), keep_guidance: bool = True
                      ) -> bpy.types.Mesh:
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
    (carry_edge_flags); creases and bevel weights are not carried.
    """
    out = bpy.data.meshes.new(name)
    fill_geometry(out, result.vertices, result.triangles)
    kept = np.asarray(result.kept, dtype=np.int64)
    face_polygon = arrays.triangle_polygon[np.asarray(result.face_source, dtype=np.int64)]
    corner_loop = arrays.triangle_loops.reshape(-1)[np.asarray(result.corner_source, dtype=np.int64).reshape(-1)]
    m = len(result.triangles)
    if moved is None:
        moved = moved_vertices(arrays.vertices, arrays.triangles, result)

    def carried(values, domain: str, nearest: bool = False) -> np.ndarray:
        """Source values of one domain for the output's elements of that domain."""
        if domain == "POINT":
            return point_values(values, kept, moved, arrays.triangles, nearest)
        if domain == "CORNER":
            return corner_values(values, corner_loop, result.triangles, moved, arrays.triangle_loops, nearest)
        return values[face_polygon]

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
        write_uv_map(out, uv.name, carried(read_uv_map(source, uv.name), "CORNER") if m else np.zeros((0, 2)))
    if source.uv_layers.active is not None:
        out.uv_layers.active_index = source.uv_layers.active_index

    for attribute in source.attributes:
        name_ = attribute.name
        if (name_.startswith(".") or name_ in _SKIPPED_ATTRIBUTES or name_ in uv_names
                or attribute.domain not in ("POINT", "FACE", "CORNER") or (name_ in guidance and not keep_guidance)):
            continue
        count = _domain_size(source, attribute.domain)
        read = read_attribute(attribute, count)
        if read is None:
            continue
        values, key = read
        target = attribute_for_write(out, name_, attribute.data_type, attribute.domain)
        picked = carried(values, attribute.domain, nearest=attribute.data_type not in _INTERPOLATED)
        if len(picked):
            target.data.foreach_set(key, np.ascontiguousarray(picked).ravel())
    _display_colors(source, out, guidance)
    carry_edge_flags(source, out, kept, moved.face >= 0)

    normals = read_custom_normals(source)
    if normals is not None and m:
        if hasattr(out, "use_auto_smooth"):  # Blender < 4.1 needs auto smooth for custom normals
            out.use_auto_smooth = True
            out.auto_smooth_angle = source.auto_smooth_angle
        corner_normals = carried(normals, "CORNER")
        mixed = moved.face[np.asarray(result.triangles).ravel()] >= 0  # interpolated: unit length again
        length = np.linalg.norm(corner_normals[mixed], axis=1, keepdims=True)
        corner_normals[mixed] = corner_normals[mixed] / np.where(length > 0, length, 1)
        flat = flat_corners(source, normals, corner_loop)
        corner_normals[flat] = np.repeat(face_normals(result.vertices, result.triangles), 3, axis=0)[flat]
        out.normals_split_custom_set(corner_normals)
    out.update()
    return out
