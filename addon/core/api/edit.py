"""Topology editing on numpy arrays (thesis 4.2.2; docs/design.md §4.5).

Delete faces, cut along a closed edge loop, fill holes, and remove a handle or tunnel (cut along
its loop, fill both holes: the genus drops by one and nothing else changes).

Every function leaves its input arrays untouched and returns an :class:`EditResult`: the new
arrays and, for every new vertex, triangle and corner, where it came from in the input. The
``*_attribute`` methods carry UVs, colours, materials or vertex groups over with those maps;
only what an edit creates (hole patches) needs made-up values, and they take them from the
hole's surroundings.

>>> from topstoc.core.api import edit
>>> result = edit.remove_handle(vertices, triangles, loop)      # loop: vertex ids in order
>>> uvs = result.corner_attribute(corner_uvs)                    # (m, 3, 2) -> (m', 3, 2)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional, Sequence

import numpy as np

from .mesh import as_vertices
from ..support import params
from ..support.native import engine
from ..support.errors import TopStocError
from ..support.counts import MeshCounts

#: Patch methods, from the thesis' planar projection to the last resort (hole_triangulation.hpp).
FILL_METHODS = ("planar", "minimum_weight", "split", "fan")


@dataclass(frozen=True)
class BoundaryLoop:
    """A boundary loop (hole): its vertices in order, the surface on their left.

    ``nonmanifold_vertex`` is a vertex of the loop where the boundary is not manifold (it
    touches another loop, or its triangles form several fans), or None. ``lone_triangle``:
    the loop borders a component of one triangle. Either way the loop cannot be filled.
    """

    vertices: np.ndarray
    nonmanifold_vertex: Optional[int] = None
    lone_triangle: bool = False

    @property
    def fillable(self) -> bool:
        return self.nonmanifold_vertex is None and not self.lone_triangle

    def __len__(self) -> int:
        return len(self.vertices)


@dataclass(frozen=True)
class CutSide:
    """The copies of a cut loop on one side, oriented like a boundary loop.

    Closed for a loop inside the surface; a path where the loop touched the mesh boundary.
    """

    vertices: np.ndarray
    closed: bool


@dataclass(frozen=True)
class Patch:
    """One filled hole: triangles ``triangles`` and added vertices ``vertices`` of the result."""

    hole: int                   #: index of the hole (into boundary_loops(), or the loops given)
    boundary: np.ndarray        #: its vertices (result ids), in the patch's orientation
    triangles: slice            #: the patch's triangles in the result
    vertices: slice             #: the vertices it added (empty unless refined, faired or a fan)
    method: str                 #: one of FILL_METHODS: the last resort any part of it needed
    normal: np.ndarray          #: the projection plane's normal, or the boundary's Newell normal
    refined: bool = False       #: refined towards the surrounding edge length
    faired: bool = False        #: and faired


@dataclass(frozen=True)
class EditResult(MeshCounts):
    """A new mesh and how it maps to the edit's input.

    ``vertex_source[i]`` is the input vertex that vertex ``i`` copies (-1 for a vertex the edit
    created); ``face_source[j]`` the input triangle that triangle ``j`` is (-1 for a patch
    triangle); ``corner_source[j, c]`` the input corner (``3 * triangle + slot``) whose data
    corner ``(j, c)`` takes, -1 if none. A triangle with a source keeps its corner order.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    vertex_source: np.ndarray
    face_source: np.ndarray
    corner_source: np.ndarray
    input_vertices: int
    input_triangles: int
    cut_sides: List[CutSide] = field(default_factory=list)
    patches: List[Patch] = field(default_factory=list)

    def vertex_map(self) -> np.ndarray:
        """For each input vertex, its new id (the first copy when a cut split it), or -1."""
        out = np.full(self.input_vertices, -1, dtype=np.int32)
        new_ids = np.flatnonzero(self.vertex_source >= 0)
        sources, first = np.unique(self.vertex_source[new_ids], return_index=True)
        out[sources] = new_ids[first]
        return out

    def face_map(self) -> np.ndarray:
        """For each input triangle, its new index, or -1 if deleted."""
        out = np.full(self.input_triangles, -1, dtype=np.int32)
        kept = np.flatnonzero(self.face_source >= 0)
        out[self.face_source[kept]] = kept
        return out

    def vertex_attribute(self, values, fill=None) -> np.ndarray:
        """Per-vertex data (n, ...) carried to the new vertices (n', ...).

        Vertices the edit created get ``fill``, or with None the mean over their patch's boundary.
        """
        values = _rows(values, self.input_vertices, "vertex")
        out = _gather(values, self.vertex_source, fill)
        if fill is None:
            for patch in self.patches:
                if patch.vertices.stop > patch.vertices.start:
                    sources = self.vertex_source[patch.boundary]
                    out[patch.vertices] = values[sources].mean(axis=0).astype(values.dtype)
        return out

    def face_attribute(self, values, fill=None) -> np.ndarray:
        """Per-triangle data (m, ...) carried to the new triangles (m', ...).

        Patch triangles get ``fill``, or with None the value of a triangle next to the hole.
        """
        values = _rows(values, self.input_triangles, "triangle")
        source = self.face_source
        if fill is None:
            # A corner of a patch triangle at an old vertex names a triangle next to the hole.
            next_to = self.corner_source.max(axis=1) // 3
            source = np.where(source >= 0, source, np.where(next_to >= 0, next_to, -1))
        return _gather(values, source, fill)

    def corner_attribute(self, values, fill=None) -> np.ndarray:
        """Per-corner data, shaped (m, 3, ...) or flat (3m, ...), carried to the new corners.

        Patch corners at old vertices take a neighbouring triangle's corner there (UVs then
        continue across the hole's border); corners at created vertices get ``fill``, or with
        None the mean over their patch's other corners. The result has the input's layout.
        """
        values = np.asarray(values)
        m = self.input_triangles
        if values.ndim >= 2 and values.shape[:2] == (m, 3):
            shaped, flat = True, values.reshape((3 * m,) + values.shape[2:])
        elif values.ndim >= 1 and values.shape[0] == 3 * m:
            shaped, flat = False, values
        else:
            raise TopStocError(f"corner data must be shaped ({m}, 3, ...) or ({3 * m}, ...), got {values.shape}")
        source = self.corner_source.reshape(-1)
        out = _gather(flat, source, fill)
        if fill is None:
            for patch in self.patches:
                rows = np.arange(3 * patch.triangles.start, 3 * patch.triangles.stop)
                known, unknown = rows[source[rows] >= 0], rows[source[rows] < 0]
                if len(known) and len(unknown):
                    out[unknown] = out[known].mean(axis=0).astype(out.dtype)
        return out.reshape((self.num_triangles, 3) + values.shape[2:]) if shaped else out


def _rows(values, count: int, what: str) -> np.ndarray:
    values = np.asarray(values)
    if values.ndim == 0 or values.shape[0] != count:
        raise TopStocError(f"per-{what} data must have one row per input {what} ({count}), got shape {values.shape}")
    return values


def _gather(values: np.ndarray, source: np.ndarray, fill) -> np.ndarray:
    """values[source] with rows where source < 0 set to fill (0 when fill is None)."""
    valid = source >= 0
    out = np.zeros((len(source),) + values.shape[1:], dtype=values.dtype)
    out[valid] = values[source[valid]]
    if fill is not None:
        out[~valid] = fill
    return out


def _result(raw: dict, vertices: np.ndarray, triangles) -> EditResult:
    sides = [CutSide(vertices=s["vertices"], closed=bool(s["closed"])) for s in raw["cut_sides"]]
    patches = [Patch(hole=int(p["hole"]), boundary=p["boundary"],
                     triangles=slice(p["first_triangle"], p["first_triangle"] + p["num_triangles"]),
                     vertices=slice(p["first_vertex"], p["first_vertex"] + p["num_vertices"]),
                     method=p["method"], normal=p["normal"], refined=bool(p["refined"]),
                     faired=bool(p["faired"])) for p in raw["patches"]]
    return EditResult(vertices=raw["vertices"], triangles=raw["triangles"],
                      vertex_source=raw["vertex_source"], face_source=raw["face_source"],
                      corner_source=raw["corner_source"], input_vertices=len(vertices),
                      input_triangles=len(triangles), cut_sides=sides, patches=patches)


def _loop(loop) -> np.ndarray:
    array = np.asarray(loop)
    if array.ndim != 1 or (array.size and array.dtype.kind not in "iu"):
        raise TopStocError(f"a loop must be a 1-D sequence of vertex ids, got {array.dtype} array of shape {array.shape}")
    return array.astype(np.int64)


def _fill_options(planar: bool, max_dp_corners: int, refine: bool, fair: bool) -> dict:
    return dict(planar=bool(planar), max_dp_corners=params.integer("max_dp_corners", max_dp_corners, 3, 2**31 - 1),
                refine=bool(refine), fair=bool(fair))


def boundary_loops(vertices, triangles) -> List[BoundaryLoop]:
    """Every boundary loop (hole), ordered by its lowest vertex, which it starts at.

    The index of a loop in this list is what ``fill_holes(holes=...)`` takes.
    """
    vertices = as_vertices(vertices)
    return [BoundaryLoop(vertices=ids, nonmanifold_vertex=None if bad < 0 else int(bad), lone_triangle=bool(lone))
            for ids, bad, lone in engine.boundary_loops(triangles, len(vertices))]


def delete_faces(vertices, triangles, faces) -> EditResult:
    """Deletes triangles, given as indices or a boolean mask over the triangles.

    Vertices only the deleted triangles used are dropped too (vertices that were already
    isolated stay); everything else keeps its relative order.
    """
    faces = np.asarray(faces)
    if faces.dtype == bool:
        if faces.shape != (len(triangles),):
            raise TopStocError(f"a face mask needs one entry per triangle ({len(triangles)}), got shape {faces.shape}")
        faces = np.flatnonzero(faces)
    elif faces.ndim != 1 or (faces.size and faces.dtype.kind not in "iu"):
        raise TopStocError(f"faces must be triangle indices or a boolean mask, got {faces.dtype} array "
                           f"of shape {faces.shape}")
    vertices = as_vertices(vertices)
    return _result(engine.delete_faces(vertices, triangles, faces.astype(np.int64)), vertices, triangles)


def cut_along_loop(vertices, triangles, loop: Sequence[int]) -> EditResult:
    """Cuts the surface open along a closed edge loop (vertex ids in order, not repeated).

    Each loop vertex is split into one copy per side; ``cut_sides`` lists the two new
    boundary loops (one for a one-sided loop). Positions and ids of existing vertices are kept.
    """
    vertices = as_vertices(vertices)
    return _result(engine.cut_along_loop(vertices, triangles, _loop(loop)), vertices, triangles)


def fill_holes(vertices, triangles, holes: Optional[Sequence[int]] = None, *, max_edges: Optional[int] = None,
               skip_unfillable: bool = False, weld_pinches: bool = True, planar: bool = True,
               max_dp_corners: int = 300, refine: bool = False, fair: bool = False) -> EditResult:
    """Fills holes: the ones listed (indices into :func:`boundary_loops`) or all of them.

    With ``holes=None``, every hole with at most ``max_edges`` edges (any size if None);
    ``skip_unfillable`` leaves holes that are not :attr:`BoundaryLoop.fillable` open instead of
    raising.
    A hole whose border passes twice through one point (two vertices at exactly the same
    position) cannot be filled without degenerate or overlapping triangles; ``weld_pinches``
    merges such vertices and fills each lobe on its own (one patch per lobe, the duplicate
    vertices removed; ``vertex_source`` still maps every vertex).
    Each patch is first triangulated on the hole's best-fit plane (``planar``), then by a
    minimum-weight triangulation for holes up to ``max_dp_corners`` vertices, else split; see
    :data:`FILL_METHODS`. ``refine`` adds vertices to match the surrounding density and
    ``fair`` (implies refine) smooths them into the surrounding surface.
    """
    if holes is not None:
        holes = np.atleast_1d(np.asarray(holes))
        if holes.size == 0:
            raise TopStocError("holes is empty: pass None to fill every hole")
        if holes.dtype.kind not in "iu":
            raise TopStocError(f"holes must be loop indices, got {holes.dtype}")
        holes = holes.astype(np.int64)
    max_edges = params.optional_integer("max_edges", max_edges, 3, 2**31 - 1)
    vertices = as_vertices(vertices)
    raw = engine.fill_holes(vertices, triangles, holes, max_edges=max_edges or 0, skip_unfillable=skip_unfillable,
                            weld_pinches=weld_pinches, **_fill_options(planar, max_dp_corners, refine, fair))
    return _result(raw, vertices, triangles)


def fill_loops(vertices, triangles, loops: Sequence[Sequence[int]], *, planar: bool = True,
               max_dp_corners: int = 300, refine: bool = False, fair: bool = False) -> EditResult:
    """Fills holes given as boundary cycles of vertex ids (either direction)."""
    vertices = as_vertices(vertices)
    raw = engine.fill_loops(vertices, triangles, [_loop(loop) for loop in loops],
                            **_fill_options(planar, max_dp_corners, refine, fair))
    return _result(raw, vertices, triangles)


def remove_handle(vertices, triangles, loop: Sequence[int], *, allow_separating: bool = False,
                  separation: float = 0.25, planar: bool = True, max_dp_corners: int = 300, refine: bool = False,
                  fair: bool = False, allow_self_intersections: bool = False, step_down: bool = False) -> EditResult:
    """Removes the handle or tunnel that ``loop`` goes around: cut along it, fill both holes.

    The genus of that component drops by one; components and boundary loops stay. A loop that
    goes around nothing (it splits its component) raises ValueError unless
    ``allow_separating``; so does a loop touching the mesh boundary.

    Only the loop's vertices move: each copy goes ``separation`` of the way towards its
    neighbours on its own side (less where a triangle would turn over), so the two patches do
    not lie on top of each other; 0 leaves them in place, coinciding.

    The edit never makes the surface intersect itself: when a patch (or a moved triangle)
    would cross the surface, the copies are pulled apart more or less and refined, faired
    patches are tried; if none is free of intersections, ValueError names the problem (a
    shorter loop around the same handle usually works: see topstoc.core.api.loops).
    ``allow_self_intersections=True`` returns the first candidate instead. ``step_down=True``
    then tries refined flat patches, then flat ones, before giving up (``Patch.refined`` and
    ``Patch.faired`` say which were kept).
    """
    vertices = as_vertices(vertices)
    raw = engine.remove_handle(vertices, triangles, _loop(loop), allow_separating=allow_separating,
                               separation=params.number("separation", separation, 0, 1, high_open=True),
                               allow_self_intersections=bool(allow_self_intersections), step_down=bool(step_down),
                               **_fill_options(planar, max_dp_corners, refine, fair))
    return _result(raw, vertices, triangles)


__all__ = [
    "BoundaryLoop", "CutSide", "EditResult", "FILL_METHODS", "Patch", "boundary_loops", "cut_along_loop",
    "delete_faces", "fill_holes", "fill_loops", "remove_handle",
]
