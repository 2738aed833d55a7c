"""Carrying a file's attributes through a decimation: UV seams in, UVs, colours and materials out.

TopStoc's output vertices are input vertices and each output triangle lies inside one input
region, so attributes carry over exactly when the decimation is told where they change:
materials as per-triangle regions, UV seams as flagged edges (``Mesh.decimate(regions=...,
borders=...)``). Afterwards ``DecimateResult.corner_source`` and ``face_source`` say which input
corner and triangle each output corner and triangle takes its attributes from.

The quality mode moves free vertices (optimal placement; never vertices on a border or seam).
A moved vertex takes its attributes interpolated, barycentrically, from the closest input
triangle of the region it stands for (the input triangles touching its cluster): the weights
lie in [0, 1] and sum to 1, so every value stays within the range of that triangle's corners.
Vertices that did not move keep their input corner's values exactly. Sparse per-vertex weights
(Blender's vertex groups, the skin) mix the same way, group by group (``point_weights``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..api.io import MeshData
from .look_fit import fit_look, vertex_means
from .appearance import fill_missing_uvs
from ..support.native import engine
from ..support.ranges import matching_rows


def uv_seam_edges(triangles, corner_uvs) -> np.ndarray:
    """Edges whose triangles disagree on the UVs at its ends: (k, 2) int32 vertex pairs.

    triangles: (m, 3) vertex ids; corner_uvs: (m, 3, 2). Boundary edges are not seams (they
    are borders anyway). Triangles with a repeated vertex are ignored, as topstoc.Mesh drops
    them; corners without UVs (NaN) match each other.
    """
    def differ(a, b):
        return ~((a == b) | (np.isnan(a) & np.isnan(b))).all(axis=1)

    return _seam_edges(triangles, np.asarray(corner_uvs, dtype=np.float64).reshape(-1, 3, 2), differ)


#: Degrees: corner normals further apart than this at a vertex make a hard edge. As Blender's auto
#: smooth (30°): a flat-shaded asset, whose custom normals differ at every edge, breaks its shading
#: only at its creases; at 1° every edge was a border and such an asset could not be decimated.
HARD_NORMAL_ANGLE = 30.0
#: Degrees: a corner whose custom normal is this close to its face's normal is flat shaded.
FLAT_CORNER_ANGLE = 1.0


def hard_normal_edges(triangles, corner_normals, angle: float = HARD_NORMAL_ANGLE) -> np.ndarray:
    """Edges whose triangles disagree on the (unit) normals at its ends by more than ``angle``
    degrees, a hard edge of custom split normals: (k, 2) int32 vertex pairs; as uv_seam_edges."""
    limit = 2 * np.sin(np.radians(angle) / 2)  # chord between unit vectors that far apart

    def differ(a, b):
        return (np.linalg.norm(a[:, :3] - b[:, :3], axis=1) > limit) | (np.linalg.norm(a[:, 3:] - b[:, 3:], axis=1) > limit)

    return _seam_edges(triangles, np.asarray(corner_normals, dtype=np.float64).reshape(-1, 3, 3), differ)


def _seam_edges(triangles, corner_values, differ) -> np.ndarray:
    """Edges whose triangles' corner values at its ends ``differ`` (a test on rows of both ends'
    values, lower vertex first, against the edge's first triangle's)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    values = np.asarray(corner_values)
    k = values.shape[2]
    keep = (t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])
    t, values = t[keep], values[keep]
    if len(t) == 0:
        return np.zeros((0, 2), dtype=np.int32)
    nxt = [1, 2, 0]
    a, b = t.ravel(), t[:, nxt].ravel()
    value_a, value_b = values.reshape(-1, k), values[:, nxt].reshape(-1, k)
    # Orient every half-edge from its lower to its higher vertex, values along with it.
    flip = a > b
    low, high = np.where(flip, b, a), np.where(flip, a, b)
    value_low = np.where(flip[:, None], value_b, value_a)
    value_high = np.where(flip[:, None], value_a, value_b)
    both = np.concatenate([value_low, value_high], axis=1)
    keys, first, group = np.unique(low * (high.max() + 1) + high, return_index=True, return_inverse=True)
    differs = np.zeros(len(keys), dtype=bool)
    np.logical_or.at(differs, group, differ(both, both[first][group]))
    seams = first[differs]
    return np.stack([low[seams], high[seams]], axis=1).astype(np.int32)


def material_regions(data: MeshData) -> Optional[np.ndarray]:
    """Per-triangle material ids when the mesh has more than one material, else None."""
    if data.triangle_material is None or len(np.unique(data.triangle_material)) < 2:
        return None
    return data.triangle_material


@dataclass
class MovedVertices:
    """Where each output vertex's attributes come from: its kept input vertex (``face`` -1), or,
    for a vertex that does not stand at its input vertex, barycentric ``weights`` in input
    triangle ``face``."""

    face: np.ndarray     #: (n_out,) int64 input triangle, -1 for vertices that did not move
    weights: np.ndarray  #: (n_out, 3) float64, in [0, 1], summing to 1

    @property
    def moved(self) -> np.ndarray:
        """Output vertices that moved."""
        return np.flatnonzero(self.face >= 0)

    def source_corners(self, triangles, vertices) -> np.ndarray:
        """(k, 3) int64 input vertices of the source triangles of the moved output ``vertices``
        (gathered before widening: ``triangles`` may be the whole input mesh; None: the corners
        in order, 3 t + c)."""
        if triangles is None:
            return 3 * self.face[vertices][:, None].astype(np.int64) + np.arange(3)
        return np.asarray(triangles)[self.face[vertices]].astype(np.int64)


def moved_vertices(vertices, triangles, result) -> MovedVertices:
    """For each output vertex of ``result`` (a DecimateResult of the mesh ``vertices``,
    ``triangles``) that does not stand at its input vertex: the input triangle and barycentric
    weights its attributes come from. The triangle is the closest (after clamping into it) among
    the input triangles touching the vertex's cluster, the lowest triangle id on ties (the
    engine's moved_sources: one pass over the input triangles)."""
    input_vertices = np.asarray(vertices, dtype=np.float64)
    out_vertices = np.asarray(result.vertices, dtype=np.float64)
    kept = np.asarray(result.kept, dtype=np.int64)
    moved = np.any(out_vertices != input_vertices[kept], axis=1)
    if not moved.any():
        face = np.full(len(out_vertices), -1, dtype=np.int64)
        weights = np.zeros((len(out_vertices), 3))
        weights[:, 0] = 1.0
        return MovedVertices(face, weights)
    face, weights = engine.moved_sources(input_vertices, triangles, result.labels, out_vertices,
                                         moved.view(np.uint8))
    return MovedVertices(face, weights)


def moved_vertices_of(mesh, result) -> MovedVertices:
    """``moved_vertices`` of ``result`` read from ``mesh``, the prepared core Mesh it was decimated
    from, so that a big decimation need not take the input arrays back (24 bytes a triangle beside
    the prepared mesh); from the arrays when the mesh dropped triangles (degenerate, repeated)."""
    if len(mesh.native.report["dropped_triangles"]):
        return moved_vertices(mesh.vertices, mesh.triangles, result)
    face, weights = engine.moved_sources_of_mesh(mesh.native, result.labels, result.kept, result.vertices)
    return MovedVertices(face, weights)


def _combine(values: np.ndarray, corners: np.ndarray, weights: np.ndarray, nearest: bool) -> np.ndarray:
    """values at ``corners`` (k, 3) combined with ``weights`` (k, 3): barycentric, or the value
    of the heaviest corner (``nearest``: integers, flags, rotations)."""
    if nearest:
        return values[corners[np.arange(len(corners)), np.argmax(weights, axis=1)]]
    mixed = np.einsum("kj,kj...->k...", weights, values[corners].astype(np.float64))
    return mixed.astype(values.dtype, copy=False)


def point_values(values, kept, moved: MovedVertices, triangles, nearest: bool = False) -> np.ndarray:
    """Per-vertex ``values`` (one row per input vertex) for the output vertices: the kept vertex's
    where the vertex did not move, else interpolated in its source triangle."""
    values = np.asarray(values)
    out = values[np.asarray(kept, dtype=np.int64)].copy()
    at = moved.moved
    if len(at):
        corners = moved.source_corners(triangles, at)
        out[at] = _combine(values, corners, moved.weights[at], nearest)
    return out


@dataclass
class SparseWeights:
    """Sparse per-vertex weights (Blender's vertex groups): one entry per (vertex, group) that
    has a weight; a vertex without an entry for a group is not in it."""

    vertex: np.ndarray  #: (k,) int64
    group: np.ndarray   #: (k,) int64
    weight: np.ndarray  #: (k,) float64

    def normalised(self, tolerance: float = 1e-4) -> bool:
        """True when every vertex with an entry has weights summing to 1 (within ``tolerance``)."""
        if len(self.vertex) == 0:
            return False
        rows, inverse = np.unique(self.vertex, return_inverse=True)
        sums = np.bincount(inverse, weights=self.weight, minlength=len(rows))
        return bool(np.all(np.abs(sums - 1.0) <= tolerance))


def point_weights(weights: SparseWeights, kept, moved: MovedVertices, triangles,
                  normalise: bool = False) -> SparseWeights:
    """Sparse per-vertex ``weights`` (rows are input vertices) for the output vertices.

    A vertex that did not move takes its kept vertex's entries exactly (zero weights too). A
    moved vertex takes, for every group any corner of its source triangle is in, the barycentric
    mix of the corners' weights (a corner outside the group counts 0), so it can join a group
    only a neighbour was in; mixes that come out 0 are dropped. Mixing keeps sums: corners whose
    weights sum to 1 give a vertex whose weights sum to 1. ``normalise`` rescales each moved
    vertex's weights to sum to 1 (a normalised skin, whose triangles may still have a corner
    without weights)."""
    kept = np.asarray(kept, dtype=np.int64)
    order = np.argsort(np.asarray(weights.vertex, dtype=np.int64), kind="stable")
    vertex = np.asarray(weights.vertex, dtype=np.int64)[order]
    group = np.asarray(weights.group, dtype=np.int64)[order]
    weight = np.asarray(weights.weight, dtype=np.float64)[order]
    # (output vertex, input vertex, factor): the kept vertex, or the three corners of the source triangle
    at = moved.moved
    still = np.flatnonzero(moved.face < 0)
    pair_out = np.concatenate([still, np.repeat(at, 3)])
    pair_in = np.concatenate([kept[still], moved.source_corners(triangles, at).ravel()])
    pair_factor = np.concatenate([np.ones(len(still)), moved.weights[at].ravel()])
    # every entry of each pair's input vertex
    entry, count = matching_rows(vertex, pair_in)
    out_vertex = np.repeat(pair_out, count)
    out_group = group[entry]
    out_weight = weight[entry] * np.repeat(pair_factor, count)
    # a moved vertex's corners contribute to the same groups: sum them
    groups = int(group.max()) + 1 if len(group) else 1
    keys, inverse = np.unique(out_vertex * groups + out_group, return_inverse=True)
    summed = np.bincount(inverse, weights=out_weight, minlength=len(keys))
    out_vertex, out_group = keys // groups, keys % groups
    is_moved = moved.face[out_vertex] >= 0
    keep = ~is_moved | (summed != 0.0)
    out_vertex, out_group, summed, is_moved = out_vertex[keep], out_group[keep], summed[keep], is_moved[keep]
    if normalise and is_moved.any():
        sums = np.bincount(out_vertex[is_moved], weights=summed[is_moved], minlength=len(moved.face))
        scale = sums[out_vertex[is_moved]]
        summed[is_moved] = summed[is_moved] / np.where(scale > 0, scale, 1.0)
    return SparseWeights(out_vertex, out_group, summed)


def corner_values(values, corner_source, output_triangles, moved: MovedVertices, triangle_corners,
                  nearest: bool = False) -> np.ndarray:
    """Per-corner ``values`` for the output corners (flat, 3 per output triangle).

    values: one row per input corner; corner_source: the input corner each output corner copies
    (flat); triangle_corners: (m, 3) the input corner of each input triangle's corners (None: the
    corners in order, 3 t + c). Corners
    of moved vertices are interpolated in the vertex's source triangle, from that triangle's own
    corners, so a value that differs across a seam never mixes the two sides."""
    values = np.asarray(values)
    out = values[np.asarray(corner_source, dtype=np.int64).ravel()].copy()
    corner_vertex = np.asarray(output_triangles, dtype=np.int64).ravel()
    at = np.flatnonzero(moved.face[corner_vertex] >= 0)
    if len(at):
        vertex = corner_vertex[at]
        corners = moved.source_corners(triangle_corners, vertex)
        out[at] = _combine(values, corners, moved.weights[vertex], nearest)
    return out


def _fitted_look(data: MeshData, result, uvs, colors) -> tuple:
    """The carried ``uvs`` (per output corner) and ``colors`` (per output vertex) fitted to the
    source's (look_fit); corners without a UV stay without."""
    triangles = np.asarray(result.triangles, dtype=np.int64)
    layers, missing = {}, None
    source_uvs = None if uvs is None else fill_missing_uvs(data.triangles, data.corner_uvs)[0]
    if source_uvs is not None:
        missing = ~np.isfinite(uvs).all(axis=1)
        layers["uv"] = (source_uvs, np.where(missing[:, None], 0.0, uvs), "uv")
    if colors is not None:
        layers["color"] = (data.vertex_colors[data.triangles], colors[triangles].reshape(-1, colors.shape[1]), "color")
    fitted = fit_look(data.vertices, data.triangles, result.vertices, triangles, layers, result.kept)
    if source_uvs is not None:
        uvs = np.where(missing[:, None], np.nan, fitted["uv"])
    if colors is not None:
        colors = vertex_means(fitted["color"], triangles, len(colors)).astype(colors.dtype, copy=False)
    return uvs, colors


def transfer_attributes(data: MeshData, result, fit: bool = False) -> MeshData:
    """The decimated mesh ``result`` (a DecimateResult of ``data``) with ``data``'s UVs,
    vertex colours and materials carried over through its source maps; moved vertices
    interpolate them (see the module docs). ``fit`` (the look was in the cost): UVs and colours
    are then fitted to the source's (look_fit; corners without a UV stay without)."""
    face_source = np.asarray(result.face_source, dtype=np.int64)
    need = data.corner_uvs is not None or data.vertex_colors is not None
    moved = moved_vertices(data.vertices, data.triangles, result) if need else None
    uvs = colors = None
    if data.corner_uvs is not None:
        uvs = corner_values(data.corner_uvs.reshape(-1, 2), result.corner_source, result.triangles, moved, None)
    if data.vertex_colors is not None:
        colors = point_values(data.vertex_colors, result.kept, moved, data.triangles)
    if fit and need and len(result.triangles):
        uvs, colors = _fitted_look(data, result, uvs, colors)
    uvs = None if uvs is None else uvs.reshape(-1, 3, 2)
    materials = None if data.triangle_material is None else data.triangle_material[face_source]
    return MeshData(vertices=result.vertices, triangles=result.triangles, corner_uvs=uvs, vertex_colors=colors,
                    triangle_material=materials, material_names=data.material_names,
                    material_libraries=data.material_libraries, file_normals=data.file_normals)
