"""Reading a Blender mesh as the engine takes it: positions and the loop triangulation.

Reading triangulates n-gons through Blender's loop triangles and keeps, for every triangle,
its polygon and the loop of each corner, so results can take every attribute exactly from
the face and corner they came from (mesh_write.build_result_mesh). Also the corners' vertices and
edges, smooth flags and custom split normals.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import bpy
import numpy as np

from ...core.support.digest import array_digest
from ...core.support import fresh_memory
from . import dna_arrays
from .mesh_access import read_array, read_indices, typed_attribute


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


def check_mesh_object(obj, error: type) -> None:
    """Raises ``error`` (a TopStocError) unless ``obj`` is a mesh object whose data can be read
    (not in Edit Mode, where the mesh datablock lags behind the edit mesh)."""
    if obj is None or obj.type != "MESH":
        raise error(f"'{getattr(obj, 'name', obj)}' is not a mesh object")
    if obj.mode == "EDIT":
        raise error(f"'{obj.name}' is in Edit Mode; switch to Object Mode")


def position_attribute(mesh):
    """The "position" attribute where Blender keeps positions as a plain float3 array (3.5+).
    Its foreach_get/set copy the array at once; MeshVertex.co goes through RNA one vertex at a time
    there, tens of times slower."""
    if bpy.app.version < (3, 5, 0):  # positions live in MVert; a layer of that name is the user's
        return None
    return typed_attribute(mesh, "position", "POINT", "FLOAT_VECTOR")


def read_positions(mesh) -> np.ndarray:
    """(n, 3) float32 vertex positions (object-local)."""
    attribute = position_attribute(mesh)
    return read_array(attribute.data if attribute is not None else mesh.vertices,
                "vector" if attribute is not None else "co", len(mesh.vertices), 3, np.float32)


def read_polygon_smooth(mesh) -> Optional[np.ndarray]:
    """Every polygon's smooth flag, or None when all are smooth (Blender 4.0+ without a
    "sharp_face" attribute)."""
    sharp = typed_attribute(mesh, "sharp_face", "FACE", "BOOLEAN")
    if sharp is not None:
        return ~read_array(sharp.data, "value", len(mesh.polygons), 1, bool)
    if bpy.app.version >= (4, 0, 0):
        return None
    return read_array(mesh.polygons, "use_smooth", len(mesh.polygons), 1, bool)


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
        return read_array(layer.data, "value", len(mesh.loops), 1, np.int32)
    legacy = dna_arrays.loop_indices(mesh, dna_field)
    return legacy if legacy is not None else read_indices(mesh.loops, key, len(mesh.loops))


def _triangle_polygons(mesh, count: int) -> np.ndarray:
    if hasattr(mesh, "loop_triangle_polygons"):  # Blender 4.0+
        return read_array(mesh.loop_triangle_polygons, "value", count, 1, np.int32)
    return read_indices(mesh.loop_triangles, "polygon_index", count)


def _polygon_materials(mesh) -> np.ndarray:
    p = len(mesh.polygons)
    attribute = mesh.attributes.get("material_index")
    if attribute is not None and attribute.domain == "FACE":
        return read_array(attribute.data, "value", p, 1, np.int32)
    if len(mesh.materials) <= 1:
        return np.zeros(p, dtype=np.int32)
    return read_array(mesh.polygons, "material_index", p, 1, np.int32)


def _triangles_in_loop_order(mesh) -> bool:
    """True when every polygon is a triangle whose loops follow the previous polygon's (how
    Blender stores meshes). Blender triangulates such a polygon into itself, corners in loop
    order, so its loop triangles need not be read one by one."""
    p = len(mesh.polygons)
    if len(mesh.loops) != 3 * p:  # every polygon has 3 loops or more: all are triangles exactly then
        return False
    in_order = dna_arrays.triangles_in_loop_order(mesh)
    return in_order if in_order is not None else dna_arrays.every_third(read_indices(mesh.polygons, "loop_start", p))


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
        triangle_loops = read_indices(mesh.loop_triangles, "loops", m, 3)
        triangle_polygons = _triangle_polygons(mesh, m)
        triangles = corners[triangle_loops]
    return MeshArrays(vertices, triangles, triangle_polygons, triangle_loops,
                      _polygon_materials(mesh), num_edges=len(mesh.edges), num_loops=len(mesh.loops))


def read_custom_normals(mesh) -> Optional[np.ndarray]:
    """(num_loops, 3) float32 custom split normals per corner, or None when the mesh shows none:
    it has no custom normals, or (Blender < 4.1) auto smooth is off, so they are not used."""
    if not mesh.has_custom_normals:
        return None
    if hasattr(mesh, "corner_normals"):  # Blender 4.1+: custom normals are corner normals
        return read_array(mesh.corner_normals, "vector", len(mesh.loops), 3, np.float32)
    if not mesh.use_auto_smooth:  # Blender < 4.1 ignores custom normals without auto smooth
        return None
    mesh.calc_normals_split()
    return read_array(mesh.loops, "normal", len(mesh.loops), 3, np.float32)
