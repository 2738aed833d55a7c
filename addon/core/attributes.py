"""Carrying a file's attributes through a decimation: UV seams in, UVs, colours and materials out.

TopStoc's output vertices are input vertices and each output triangle lies inside one input
region, so attributes carry over exactly when the decimation is told where they change:
materials as per-triangle regions, UV seams as flagged edges (``Mesh.decimate(regions=...,
borders=...)``). Afterwards ``DecimateResult.corner_source`` and ``face_source`` say which input
corner and triangle each output corner and triangle takes its attributes from.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from .io import MeshData


def uv_seam_edges(triangles, corner_uvs) -> np.ndarray:
    """Edges whose triangles disagree on the UVs at its ends: (k, 2) int32 vertex pairs.

    triangles: (m, 3) vertex ids; corner_uvs: (m, 3, 2). Boundary edges are not seams (they
    are borders anyway). Triangles with a repeated vertex are ignored, as topstoc.Mesh drops
    them; corners without UVs (NaN) match each other.
    """
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    uv = np.asarray(corner_uvs, dtype=np.float64).reshape(-1, 3, 2)
    keep = (t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])
    t, uv = t[keep], uv[keep]
    if len(t) == 0:
        return np.zeros((0, 2), dtype=np.int32)
    nxt = [1, 2, 0]
    a, b = t.ravel(), t[:, nxt].ravel()
    uv_a, uv_b = uv.reshape(-1, 2), uv[:, nxt].reshape(-1, 2)
    # Orient every half-edge from its lower to its higher vertex, UVs along with it.
    flip = a > b
    low, high = np.where(flip, b, a), np.where(flip, a, b)
    uv_low = np.where(flip[:, None], uv_b, uv_a)
    uv_high = np.where(flip[:, None], uv_a, uv_b)
    values = np.concatenate([uv_low, uv_high], axis=1)
    keys, first, group = np.unique(low * (high.max() + 1) + high, return_index=True, return_inverse=True)
    reference = values[first][group]
    same = (values == reference) | (np.isnan(values) & np.isnan(reference))
    differs = np.zeros(len(keys), dtype=bool)
    np.logical_or.at(differs, group, ~same.all(axis=1))
    seams = first[differs]
    return np.stack([low[seams], high[seams]], axis=1).astype(np.int32)


def material_regions(data: MeshData) -> Optional[np.ndarray]:
    """Per-triangle material ids when the mesh has more than one material, else None."""
    if data.triangle_material is None or len(np.unique(data.triangle_material)) < 2:
        return None
    return data.triangle_material


def transfer_attributes(data: MeshData, result) -> MeshData:
    """The decimated mesh ``result`` (a DecimateResult of ``data``) with ``data``'s UVs,
    vertex colours and materials carried over through its source maps."""
    corner_source = np.asarray(result.corner_source, dtype=np.int64)
    face_source = np.asarray(result.face_source, dtype=np.int64)
    kept = np.asarray(result.kept, dtype=np.int64)
    uvs = None
    if data.corner_uvs is not None:
        uvs = data.corner_uvs.reshape(-1, 2)[corner_source.ravel()].reshape(-1, 3, 2)
    colors = None if data.vertex_colors is None else data.vertex_colors[kept]
    materials = None if data.triangle_material is None else data.triangle_material[face_source]
    return MeshData(vertices=result.vertices, triangles=result.triangles, corner_uvs=uvs, vertex_colors=colors,
                    triangle_material=materials, material_names=data.material_names,
                    material_libraries=data.material_libraries)
