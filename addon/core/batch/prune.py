"""Pruning small disconnected parts from a coarse LOD (opt-in).

At a small screen size a bolt or a button far below a pixel only costs triangles. A part here
is a set of triangles connected through shared vertices; a part whose bounding-box diagonal is
below ``min_size`` is dropped from the decimation result, and the result's vertex, face and
corner maps are compacted so that attributes still carry over (topstoc.core.carry.attributes, the
add-on's mesh writer). Parts at or above the size are kept untouched; a result whose every
part is small keeps its largest part, so a LOD is never empty.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from ..support.errors import TopStocError


@dataclass(frozen=True)
class PruneReport:
    """What pruning removed."""

    min_size: float        #: parts with a smaller bounding-box diagonal were dropped
    parts: int             #: parts before pruning
    removed_parts: int
    removed_triangles: int
    removed_vertices: int

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def triangle_parts(num_vertices: int, triangles) -> np.ndarray:
    """Part id per triangle (parts joined through shared vertices), ids in order of first triangle.

    Vectorised hook-and-jump: every vertex and its current root take the smallest label among
    their triangles, then labels jump to their label's label, until nothing changes.
    """
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    labels = np.arange(num_vertices, dtype=np.int64)
    if len(t) == 0:
        return np.zeros(0, dtype=np.int32)
    while True:
        smallest = np.repeat(labels[t].min(axis=1), 3)
        hooked = labels.copy()
        np.minimum.at(hooked, t.reshape(-1), smallest)
        np.minimum.at(hooked, labels[t.reshape(-1)], smallest)
        while True:
            jumped = hooked[hooked]
            if np.array_equal(jumped, hooked):
                break
            hooked = jumped
        if np.array_equal(hooked, labels):
            break
        labels = hooked
    roots = labels[t[:, 0]]
    _, first, group = np.unique(roots, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))  # renumber parts by their first triangle
    return order[group].astype(np.int32)


def prune_small_parts(result, min_size: float):
    """(pruned result, PruneReport): ``result`` (a DecimateResult) without its parts smaller
    than ``min_size`` (bounding-box diagonal, world units)."""
    if not np.isfinite(min_size) or min_size < 0:
        raise TopStocError(f"the pruning size must be a non-negative number, got {min_size!r}")
    vertices = np.asarray(result.vertices, dtype=np.float64)
    triangles = np.asarray(result.triangles, dtype=np.int64)
    if len(triangles) == 0:
        return result, PruneReport(float(min_size), 0, 0, 0, 0)
    parts = triangle_parts(len(vertices), triangles)
    count = int(parts.max()) + 1
    corners = vertices[triangles.reshape(-1)]
    part_of_corner = np.repeat(parts, 3)
    low = np.full((count, 3), np.inf)
    high = np.full((count, 3), -np.inf)
    np.minimum.at(low, part_of_corner, corners)
    np.maximum.at(high, part_of_corner, corners)
    size = np.linalg.norm(high - low, axis=1)
    keep_part = size >= min_size
    if not keep_part.any():
        keep_part[int(np.argmax(size))] = True
    if keep_part.all():
        return result, PruneReport(float(min_size), count, 0, 0, 0)
    keep_triangle = keep_part[parts]
    kept_triangles = triangles[keep_triangle]
    used = np.zeros(len(vertices), dtype=bool)
    used[kept_triangles.reshape(-1)] = True
    new_index = np.full(len(vertices), -1, dtype=np.int64)
    new_index[used] = np.arange(int(used.sum()))
    labels = np.asarray(result.labels, dtype=np.int64)
    labels = np.where(labels >= 0, new_index[np.maximum(labels, 0)], -1)
    pruned = dataclasses.replace(
        result, vertices=vertices[used], triangles=new_index[kept_triangles].astype(np.int32),
        kept=np.asarray(result.kept)[used], face_source=np.asarray(result.face_source)[keep_triangle],
        corner_source=np.asarray(result.corner_source).reshape(-1, 3)[keep_triangle],
        labels=labels.astype(np.int32))
    return pruned, PruneReport(float(min_size), count, int((~keep_part).sum()),
                               int((~keep_triangle).sum()), int(len(vertices) - used.sum()))
