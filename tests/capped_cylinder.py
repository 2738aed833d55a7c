"""A closed cylinder with flat caps and hard-edge custom normals, and how far a decimation's
shading drifts from it.

The cylinder (radius 1, height 2, axis z) has radial normals on its side; its caps are flat discs
of rings whose normals are axial inside and tilt outward towards the rim (by up to TILT degrees
from radius RAMP on: a bevel the normals fake, a common hard-surface trick), so the rims are hard
edges: per-corner normals that differ at the same vertex, as a hard-surface asset's custom split
normals are. The caps' shape says nothing about their normals: only the normals can keep them.

The shading error of a result is measured on the input's surface, where the look is defined: at
fixed barycentric points of every input triangle, the normal the input shades with (its corner
normals interpolated, renormalised) against the normal the result shades with at the closest
point of its surface (its corner normals interpolated there),
as an angle in degrees, area-weighted.
"""

import numpy as np

RINGS, AROUND, CAP_RINGS = 12, 32, 8
RAMP, TILT = 0.6, 40.0


def capped_cylinder(rings: int = RINGS, around: int = AROUND, cap_rings: int = CAP_RINGS):
    """(vertices (n, 3), triangles (m, 3), corner_normals (m, 3, 3)), outward facing."""
    theta = 2 * np.pi * np.arange(around) / around
    circle = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    z = 2.0 * np.arange(rings) / (rings - 1)
    vertices = [np.c_[circle, np.full(around, h)] for h in z]
    side = np.arange(rings * around).reshape(rings, around)
    caps = []
    for height in (0.0, 2.0):  # inner rings of each cap, then its centre
        inner = [np.c_[circle * (k / cap_rings), np.full(around, height)] for k in range(cap_rings - 1, 0, -1)]
        start = sum(len(v) for v in vertices)
        vertices += inner + [np.array([[0.0, 0.0, height]])]
        caps.append((start, start + len(inner) * around))
    vertices = np.concatenate(vertices)
    triangles, normals = [], []

    def quad(a, b, c, d):
        triangles.extend([(a, b, c), (a, c, d)])

    def cap_normal(point, up):
        radius = np.hypot(point[0], point[1])
        tilt = np.radians(TILT) * max(0.0, (radius - RAMP) / (1 - RAMP))
        outward = point[:2] / radius if radius > 0 else np.zeros(2)
        return (*(np.sin(tilt) * outward), up * np.cos(tilt))

    radial = np.c_[circle, np.zeros(around)]
    for j in range(rings - 1):
        for i in range(around):
            k = (i + 1) % around
            quad(side[j, i], side[j, k], side[j + 1, k], side[j + 1, i])
    normals.extend(radial[np.array(triangles) % around])
    for (start, centre), ring0, up in ((caps[0], side[0], -1.0), (caps[1], side[-1], 1.0)):
        first = len(triangles)
        ringsets = [ring0] + [start + r * around + np.arange(around) for r in range(cap_rings - 1)]
        for outer, inner in zip(ringsets[:-1], ringsets[1:]):
            for i in range(around):
                k = (i + 1) % around
                if up > 0:
                    quad(outer[i], outer[k], inner[k], inner[i])
                else:
                    quad(outer[k], outer[i], inner[i], inner[k])
        last = ringsets[-1]
        for i in range(around):
            k = (i + 1) % around
            triangles.append((last[i], last[k], centre) if up > 0 else (last[k], last[i], centre))
        normals.extend([[cap_normal(vertices[c], up) for c in tri] for tri in triangles[first:]])
    return vertices, np.array(triangles, dtype=np.int32), np.array(normals, dtype=np.float64)


# barycentric sample points per triangle: centroid and inner points
_BARY = np.array([(1 / 3, 1 / 3, 1 / 3), (2 / 3, 1 / 6, 1 / 6), (1 / 6, 2 / 3, 1 / 6), (1 / 6, 1 / 6, 2 / 3)])


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def shading_error(vertices, triangles, corner_normals, out_vertices, out_triangles, out_normals,
                  closest_points) -> dict:
    """{"mean", "rms"}: area-weighted angle in degrees between the input's shading normal and the
    result's at the closest point (module docs); ``closest_points`` is topstoc.core.api.hausdorff's
    (passed in: inside Blender the add-on's copy of the package must be used)."""
    v, t = np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64)
    corners = v[t]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    points = np.einsum("sj,mjk->msk", _BARY, corners).reshape(-1, 3)
    expected = _unit(np.einsum("sj,mjk->msk", _BARY, corner_normals).reshape(-1, 3))
    ov, ot = np.asarray(out_vertices, dtype=np.float64), np.asarray(out_triangles, dtype=np.int64)
    _, triangle, point = closest_points((ov, ot), points)
    a, b, c = (ov[ot[triangle, i]] for i in range(3))
    weights = _barycentric(point, a, b, c)
    shaded = _unit(np.einsum("kj,kjd->kd", weights, np.asarray(out_normals)[triangle]))
    angle = np.degrees(np.arccos(np.clip((shaded * expected).sum(1), -1, 1))).reshape(len(t), len(_BARY))
    weight = np.repeat(area[:, None], len(_BARY), axis=1)
    return {"mean": float((weight * angle).sum() / weight.sum()),
            "rms": float(np.sqrt((weight * angle ** 2).sum() / weight.sum()))}


def _barycentric(p, a, b, c):
    e0, e1, d = b - a, c - a, p - a
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
    den = d00 * d11 - d01 * d01
    w1 = (d11 * d20 - d01 * d21) / den
    w2 = (d00 * d21 - d01 * d20) / den
    return np.clip(np.stack([1 - w1 - w2, w1, w2], axis=1), 0, 1)
