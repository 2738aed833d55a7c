"""The look's error between a mesh and its decimation: UV, normal and colour, per corner.

A mesh here is a dict: "vertices" (n, 3), "triangles" (m, 3) and, per triangle corner, any of
"uv" (m, 3, 2), "normal" (m, 3, 3, unit) and "color" (m, 3, 3, RGB in [0, 1]).

Definition (docs/benchmarks.md, tests/bench/bench_attributes.py): points are sampled uniformly by
area on the result and, as many, on the source (fixed seed). Each point carries the values its
triangle's corners interpolate (barycentric; normals renormalised) and is sent to the closest point
of the other mesh, whose triangle interpolates them too. Per point:
  - uv: the distance between the two UVs, in texture units (1 = the texture's width);
  - normal: the angle between the two normals, in degrees;
  - color: the Euclidean distance between the two RGB triples (0 to sqrt(3)).
A figure is the mean over both sets of points (result to source and source to result), so a
result whose look drifts and one that loses a painted region both pay.
"""

from __future__ import annotations

import numpy as np

CHANNELS = ("uv", "normal", "color")


def sample_surface(vertices, triangles, count: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(triangle (count,), barycentric (count, 3)): points uniform by area on the mesh."""
    corners = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    rng = np.random.default_rng(seed)
    triangle = rng.choice(len(area), size=count, p=area / area.sum())
    r1, r2 = np.sqrt(rng.random(count)), rng.random(count)
    return triangle, np.stack([1 - r1, r1 * (1 - r2), r1 * r2], axis=1)


def barycentric(points, vertices, triangles, triangle) -> np.ndarray:
    """(k, 3) barycentric coordinates of ``points`` in their ``triangle``s, clamped into them."""
    v, t = np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64)[triangle]
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    e0, e1, d = b - a, c - a, np.asarray(points, dtype=np.float64) - a
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
    den = np.where(d00 * d11 - d01 * d01 > 0, d00 * d11 - d01 * d01, 1.0)
    w1, w2 = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
    w = np.clip(np.stack([1 - w1 - w2, w1, w2], axis=1), 0, None)
    return w / np.maximum(w.sum(1, keepdims=True), 1e-300)


def interpolate(corner_values, triangle, weights, unit: bool = False) -> np.ndarray:
    """Values at points of ``triangle`` with barycentric ``weights``; ``unit`` renormalises."""
    mixed = np.einsum("kj,kjd->kd", weights, np.asarray(corner_values, dtype=np.float64)[triangle])
    if unit:
        mixed /= np.maximum(np.linalg.norm(mixed, axis=1, keepdims=True), 1e-300)
    return mixed


def _difference(channel: str, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if channel == "normal":
        return np.degrees(np.arccos(np.clip((a * b).sum(1), -1.0, 1.0)))
    return np.linalg.norm(a - b, axis=1)


def _one_way(start: dict, other: dict, channels, count: int, seed: int, closest_points) -> dict:
    """Per channel, the differences at ``count`` points of ``start`` against ``other``."""
    triangle, weights = sample_surface(start["vertices"], start["triangles"], count, seed)
    corners = np.asarray(start["vertices"], dtype=np.float64)[np.asarray(start["triangles"], dtype=np.int64)[triangle]]
    points = np.einsum("kj,kjd->kd", weights, corners)
    _, near, at = closest_points((np.asarray(other["vertices"], dtype=np.float64),
                                  np.asarray(other["triangles"], dtype=np.int64)), points)
    near_weights = barycentric(at, other["vertices"], other["triangles"], near)
    return {c: _difference(c, interpolate(start[c], triangle, weights, c == "normal"),
                           interpolate(other[c], near, near_weights, c == "normal")) for c in channels}


def attribute_errors(source: dict, result: dict, closest_points, count: int = 50_000, seed: int = 0) -> dict:
    """{channel: mean difference} over both directions for the channels both meshes carry
    (module docs). closest_points((vertices, triangles), points) -> (distance, triangle, point)."""
    channels = [c for c in CHANNELS if source.get(c) is not None and result.get(c) is not None]
    there = _one_way(result, source, channels, count, seed, closest_points)
    back = _one_way(source, result, channels, count, seed + 1, closest_points)
    return {c: float(np.concatenate([there[c], back[c]]).mean()) for c in channels}
