"""A UV-mapped open cylinder with a seam, and how far a decimation's UVs drift from its mapping.

The cylinder (radius 1, height 2, axis z) is unwrapped as u = theta / 2 pi (a seam where u jumps
from 1 back to 0) and v = (z / 2) ** 3: the texture is stretched along the straight axis, where
the geometry alone says nothing about which rings to keep. The mapping is known in closed form,
so the distortion of a result is measured against it, not against another mesh: at fixed
barycentric points of every output triangle, the UV the output interpolates from its corners
against the mapping's UV at that point's cylinder coordinates (theta from atan2, v from z; u
differences taken around the circle, so both sides of the seam measure alike), area-weighted.
"""

import numpy as np

RINGS, AROUND = 40, 48


def mapping(points: np.ndarray) -> np.ndarray:
    """The cylinder's UV at (near-surface) points: (k, 2)."""
    theta = np.mod(np.arctan2(points[:, 1], points[:, 0]), 2 * np.pi)
    return np.stack([theta / (2 * np.pi), (points[:, 2] / 2.0) ** 3], axis=1)


def uv_cylinder(rings: int = RINGS, around: int = AROUND):
    """(vertices (n, 3), triangles (m, 3), corner_uvs (m, 3, 2)): quads split along a diagonal,
    corners of the last column take u = 1 (the seam)."""
    theta = 2 * np.pi * np.arange(around) / around
    z = 2.0 * np.arange(rings) / (rings - 1)
    vertices = np.array([(np.cos(t), np.sin(t), h) for h in z for t in theta])
    triangles, uvs = [], []
    for j in range(rings - 1):
        for i in range(around):
            a, b = j * around + i, j * around + (i + 1) % around
            c, d = b + around, a + around
            ua, ub = i / around, (i + 1) / around  # ub = 1 at the seam
            va, vb = (z[j] / 2) ** 3, (z[j + 1] / 2) ** 3
            triangles += [(a, b, c), (a, c, d)]
            uvs += [[(ua, va), (ub, va), (ub, vb)], [(ua, va), (ub, vb), (ua, vb)]]
    return vertices, np.array(triangles, dtype=np.int32), np.array(uvs)


# barycentric sample points per triangle: corners, edge midpoints, centroid and inner points
_BARY = np.array([(1, 0, 0), (0, 1, 0), (0, 0, 1), (.5, .5, 0), (0, .5, .5), (.5, 0, .5), (1 / 3, 1 / 3, 1 / 3),
                  (2 / 3, 1 / 6, 1 / 6), (1 / 6, 2 / 3, 1 / 6), (1 / 6, 1 / 6, 2 / 3)])


def uv_distortion(vertices, triangles, corner_uvs) -> dict:
    """{"rms", "max"}: UV error of a mesh against the cylinder's mapping (module docs)."""
    v, t = np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64)
    uv = np.asarray(corner_uvs, dtype=np.float64).reshape(-1, 3, 2)
    corners = v[t]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    points = np.einsum("sj,mjk->msk", _BARY, corners).reshape(-1, 3)
    carried = np.einsum("sj,mjk->msk", _BARY, uv).reshape(-1, 2)
    d = np.abs(carried - mapping(points))
    d[:, 0] = np.minimum(d[:, 0], 1.0 - d[:, 0])  # around the seam
    error = np.linalg.norm(d, axis=1).reshape(len(t), len(_BARY))
    weight = np.repeat(area[:, None], len(_BARY), axis=1)
    return {"rms": float(np.sqrt((weight * error ** 2).sum() / weight.sum())), "max": float(error.max())}
