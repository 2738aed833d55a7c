"""remove_handle on the loop's neighbourhood only, for many small handles (docs/design.md §4.6).

``edit.remove_handle`` copies the whole mesh and tests the new triangles against all others,
so removing k handles costs k passes over the mesh. Here the edit runs on the triangles whose
bounding boxes meet the loop's box grown by the loop's length, and is spliced back. It is the
same edit when three things hold, each checked, else the whole mesh is edited:
- every triangle the edit created or moved has its bounding box inside the grown box, so every
  triangle it could cross is in the neighbourhood and was tested;
- the cut does not separate the neighbourhood (then it cannot separate the whole surface);
- the loop's vertices have all their triangles in the neighbourhood (true by construction).
"""

from __future__ import annotations

import numpy as np

from . import edit
from .edit import EditResult, Patch


class LocalEditor:
    """Removes handles locally (module docstring), keeping the triangles' bounding boxes of the
    current mesh up to date between edits, so that finding a neighbourhood reads no mesh."""

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray):
        # One row per axis, with room to grow: the scan for a neighbourhood compares six
        # contiguous rows (a tenth of the time of reducing (m, 3) arrays across their rows), and
        # an edit's new triangles are appended in place instead of copying every box.
        corners = vertices[triangles]
        self.low, self.high = np.ascontiguousarray(corners.min(axis=1).T), np.ascontiguousarray(corners.max(axis=1).T)
        self.count = len(triangles)

    def boxes(self) -> tuple:
        """(low, high) corners of the current triangles' boxes, (m, 3) each."""
        return self.low[:, :self.count].T, self.high[:, :self.count].T

    def _near(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        """The triangles whose boxes meet [low, high]."""
        lo, hi = self.low[:, :self.count], self.high[:, :self.count]
        return np.flatnonzero((hi[0] >= low[0]) & (hi[1] >= low[1]) & (hi[2] >= low[2]) &
                              (lo[0] <= high[0]) & (lo[1] <= high[1]) & (lo[2] <= high[2]))

    def remove_handle(self, vertices: np.ndarray, triangles: np.ndarray, loop: np.ndarray, **options) -> EditResult:
        """``edit.remove_handle(vertices, triangles, loop, **options)`` for the mesh this editor
        follows (the result of its previous edit); the result has the same form."""
        points = vertices[loop]
        grow = float(np.linalg.norm(points - np.roll(points, -1, axis=0), axis=1).sum())
        low, high = points.min(axis=0) - grow, points.max(axis=0) + grow
        near = self._near(low, high)
        result = None
        if len(near) * 2 <= len(triangles):
            ids = np.unique(triangles[near])
            try:
                local = edit.remove_handle(vertices[ids], np.searchsorted(ids, triangles[near]).astype(np.int32),
                                           np.searchsorted(ids, loop), **options)
            except ValueError as error:
                if "separates" not in str(error):
                    raise
                local = None
            if local is not None and _inside(local, len(ids), len(near), low, high):
                result = _splice(vertices, triangles, ids, near, local)
        if result is None:
            result = edit.remove_handle(vertices, triangles, loop, **options)
            near = np.arange(len(triangles))
        self._update(result, near, len(triangles))
        return result

    def _update(self, result: EditResult, changed: np.ndarray, m: int) -> None:
        corners = result.vertices[result.triangles[changed]]
        self.low[:, changed], self.high[:, changed] = corners.min(axis=1).T, corners.max(axis=1).T
        added = result.vertices[result.triangles[m:]]
        end = m + len(added)
        if end > self.low.shape[1]:  # double the room: appends cost their own size on average
            room = max(end, 2 * self.low.shape[1])
            self.low = np.concatenate([self.low[:, :m], np.empty((3, room - m))], axis=1)
            self.high = np.concatenate([self.high[:, :m], np.empty((3, room - m))], axis=1)
        self.low[:, m:end], self.high[:, m:end] = added.min(axis=1).T, added.max(axis=1).T
        self.count = end


def _inside(local: EditResult, n: int, m: int, low, high) -> bool:
    """Whether every triangle the local edit created or moved lies inside [low, high]."""
    moved = np.zeros(local.num_vertices, dtype=bool)
    moved[n:] = True
    for side in local.cut_sides:
        moved[side.vertices] = True
    changed = moved[local.triangles].any(axis=1)
    corners = local.vertices[local.triangles[changed]]
    return bool(np.all(corners >= low) and np.all(corners <= high))


def _splice(vertices, triangles, ids, near, local: EditResult) -> EditResult:
    """The local edit written into the whole mesh, with maps to the whole mesh."""
    n, m, n_local, m_local = len(vertices), len(triangles), len(ids), len(near)
    to_global = np.concatenate([ids, n + np.arange(local.num_vertices - n_local)]).astype(np.int32)
    out_vertices = np.concatenate([vertices, local.vertices[n_local:]])
    out_vertices[ids] = local.vertices[:n_local]  # the loop's copies moved
    out_triangles = np.concatenate([triangles, to_global[local.triangles[m_local:]]]).astype(np.int32)
    out_triangles[near] = to_global[local.triangles[:m_local]]
    new_source = local.vertex_source[n_local:]
    vertex_source = np.concatenate([np.arange(n), np.where(new_source >= 0, ids[np.maximum(new_source, 0)], -1)])
    local_corners = local.corner_source[m_local:]
    corner_global = 3 * near[local_corners // 3] + local_corners % 3
    corner_source = np.concatenate([np.arange(3 * m).reshape(m, 3),
                                    np.where(local_corners >= 0, corner_global, -1)])
    patches = [Patch(hole=p.hole, boundary=to_global[p.boundary],
                     triangles=slice(m + p.triangles.start - m_local, m + p.triangles.stop - m_local),
                     vertices=slice(n + p.vertices.start - n_local, n + p.vertices.stop - n_local),
                     method=p.method, normal=p.normal) for p in local.patches]
    return EditResult(vertices=out_vertices, triangles=out_triangles, vertex_source=vertex_source.astype(np.int32),
                      face_source=np.concatenate([np.arange(m), np.full(len(out_triangles) - m, -1)]).astype(np.int32),
                      corner_source=corner_source.astype(np.int32), input_vertices=n, input_triangles=m,
                      patches=patches)
