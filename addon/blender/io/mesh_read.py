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
    are then ``None`` inside and made afresh on each read, never kept (two arrays of 4 and 12
    bytes a triangle, which the prepared-mesh cache would hold); ``polygons_of`` and
    ``loops_of`` map a few triangles without making them."""

    _vertices: Optional[np.ndarray]   #: (n, 3) float64, None once handed over
    _triangles: Optional[np.ndarray]  #: (m, 3) int32 vertex ids (loop triangles), None once handed over
    _triangle_polygon: Optional[np.ndarray]  #: (m,) int32 polygon of each triangle
    _triangle_loops: Optional[np.ndarray]    #: (m, 3) int32 loop of each triangle corner
    polygon_material: np.ndarray  #: (p,) int32 material slot per polygon (read-only)
    num_edges: int
    num_loops: int
    _engine: object = None        #: the prepared core Mesh holding the positions and triangles
    _handed_triangles: int = 0    #: how many triangles were handed over

    @property
    def vertices(self) -> np.ndarray:
        return self._vertices if self._vertices is not None else self._engine.vertices

    @property
    def triangles(self) -> np.ndarray:
        return self._triangles if self._triangles is not None else self._engine.triangles

    def hand_over(self, mesh) -> None:
        """Drops the positions and triangles, which ``mesh`` (their prepared core Mesh) keeps a copy
        of: read again they come from it bit for bit (read-only, made on first use), so a big
        decimation runs without a second copy (24 bytes a triangle)."""
        self._engine, self._handed_triangles = mesh, self.num_triangles
        self._vertices = self._triangles = None

    @property
    def num_triangles(self) -> int:
        """len(triangles), without taking them back from the engine."""
        return len(self._triangles) if self._triangles is not None else self._handed_triangles

    @property
    def triangle_polygon(self) -> np.ndarray:
        if self._triangle_polygon is None:
            return np.arange(self.num_triangles, dtype=np.int32)
        return self._triangle_polygon

    @property
    def triangle_loops(self) -> np.ndarray:
        if self._triangle_loops is None:
            return np.arange(3 * self.num_triangles, dtype=np.int32).reshape(-1, 3)
        return self._triangle_loops

    @property
    def loop_map(self) -> Optional[np.ndarray]:
        """``triangle_loops``, or None when they are the loops in order (loop 3 t + c)."""
        return self._triangle_loops

    def polygons_of(self, triangles: np.ndarray) -> np.ndarray:
        """The polygon of each of the given triangle ids."""
        ids = np.asarray(triangles, dtype=np.int64)
        return ids if self._triangle_polygon is None else self._triangle_polygon[ids]

    def loops_of(self, corners: np.ndarray) -> np.ndarray:
        """The loop of each of the given triangle corners (flat ids, 3 t + c)."""
        ids = np.asarray(corners, dtype=np.int64).reshape(-1)
        return ids if self._triangle_loops is None else self._triangle_loops.reshape(-1)[ids]

    def several_materials(self) -> bool:
        """True when the polygons use more than one material slot (no sorted copy, as np.unique)."""
        slots = self.polygon_material
        return len(slots) > 1 and slots.strides != (0,) and bool(np.any(slots != slots[0]))

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


def _position_source(mesh) -> tuple:
    """(collection, key) whose foreach_get gives the float32 positions."""
    attribute = position_attribute(mesh)
    return (attribute.data, "vector") if attribute is not None else (mesh.vertices, "co")


def read_positions(mesh) -> np.ndarray:
    """(n, 3) float32 vertex positions (object-local)."""
    collection, key = _position_source(mesh)
    return read_array(collection, key, len(mesh.vertices), 3, np.float32)


#: values widened to float64 at a time (the temporary numpy makes where a block overlaps its source)
WIDEN_BLOCK = 1 << 20


def read_positions_float64(mesh) -> np.ndarray:
    """(n, 3) float64 vertex positions, without a float32 array n long beside them: Blender's
    float32 values land in the upper half of the float64 array's own memory and are widened in
    place front to back (value i is written below every value not yet read). A float32 copy the
    main thread frees stays in its heap while the worker decimates (6 bytes a triangle)."""
    n = len(mesh.vertices)
    out = fresh_memory.empty(3 * n, np.float64)
    narrow = out.view(np.float32)[3 * n:]
    if n:
        collection, key = _position_source(mesh)
        collection.foreach_get(key, narrow)
    for start in range(0, 3 * n, WIDEN_BLOCK):
        stop = min(start + WIDEN_BLOCK, 3 * n)
        out[start:stop] = narrow[start:stop]  # numpy copies a block first where it overlaps its source
    return out.reshape(n, 3)


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
    if len(mesh.materials) <= 1:  # all slot 0: one shared zero, no array a polygon long
        return np.broadcast_to(np.zeros(1, dtype=np.int32), (p,))
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
    # First: Blender 4.x reads the polygons' loop starts for it, freed before the big arrays take that memory
    in_order = _triangles_in_loop_order(mesh)
    vertices = read_positions_float64(mesh)
    corners = corner_vertices(mesh)
    if in_order:  # a triangle mesh: the loop triangles are the polygons
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
