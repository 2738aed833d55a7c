"""remove_handle on the loop's neighbourhood only, for many small handles (docs/design.md §4.6).

``edit.remove_handle`` copies the whole mesh and tests the new triangles against all others,
so removing k handles costs k passes over the mesh. Here the edit runs on the triangles whose
bounding boxes meet the loop's box grown by half the loop's length (then by its length, when
the first is too small), and is written back in place: moved vertices and changed triangles
over their old rows, new ones appended to arrays with room to grow, so a removal costs its
neighbourhood, not the mesh. It is the same edit when three
things hold, each checked, else the whole mesh is edited:
- every triangle the edit created or moved has its bounding box inside the grown box, so every
  triangle it could cross is in the neighbourhood and was tested;
- the cut does not separate the neighbourhood (then it cannot separate the whole surface);
- the loop's vertices have all their triangles in the neighbourhood (true by construction).
"""

from __future__ import annotations

import numpy as np

from . import edit
from ..support.errors import TopStocError
from .box_index import BoxIndex, sorted_unique
from .edit import EditResult, Patch


#: The neighbourhoods tried, smallest first: the loop's box grown by these times its length.
GROWTH = (0.5, 1.0)


class _Growing:
    """An array growing along its first axis with room to spare: an append costs its own size
    on average, not the array's."""

    def __init__(self, initial: np.ndarray):
        self.count = len(initial)
        # Room for an eighth more: a round of small removals rarely outgrows it (no doubling copy).
        self.data = np.empty((self.count + self.count // 8 + 64,) + initial.shape[1:], initial.dtype)
        self.data[:self.count] = initial

    def view(self) -> np.ndarray:
        return self.data[:self.count]

    def append(self, rows: np.ndarray) -> None:
        end = self.count + len(rows)
        if end > len(self.data):
            grown = np.empty((max(end, 2 * len(self.data)),) + self.data.shape[1:], self.data.dtype)
            grown[:self.count] = self.data[:self.count]
            self.data = grown
        self.data[self.count:end] = rows
        self.count = end


def through(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """first[second] where second >= 0, else -1 (maps composed)."""
    out = np.full(second.shape, -1, dtype=np.int32)
    valid = second >= 0
    out[valid] = first[second[valid]]
    return out


class LocalEditor:
    """Removes handles locally (module docstring) from a mesh it holds and edits in place, with
    the maps back to the mesh it was given and every triangle's bounding box kept up to date, so
    that finding a neighbourhood reads no mesh. ``result()`` is the mesh so far as an edit of
    the one given."""

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray):
        n, m = len(vertices), len(triangles)
        self._given = (n, m)
        self.vertices = _Growing(np.asarray(vertices, dtype=np.float64))
        self.triangles = _Growing(np.asarray(triangles, dtype=np.int32).reshape(-1, 3))
        self.vertex_source = _Growing(np.arange(n, dtype=np.int32))
        self.face_source = _Growing(np.arange(m, dtype=np.int32))
        self.corner_source = _Growing(np.arange(3 * m, dtype=np.int32).reshape(m, 3))
        self.patches = []
        self.box = _Growing(_boxes(self.vertices.view(), self.triangles.view()))  # (m, 6): low, high
        self.index = BoxIndex(*self.boxes())
        self._local = np.zeros(n, dtype=np.int32)  # scratch: global vertex id -> neighbourhood id

    def result(self) -> EditResult:
        """The mesh so far, with its maps to the mesh given and the patches made (arrays copied)."""
        return EditResult(vertices=self.vertices.view().copy(), triangles=self.triangles.view().copy(),
                          vertex_source=self.vertex_source.view().copy(), face_source=self.face_source.view().copy(),
                          corner_source=self.corner_source.view().copy(), input_vertices=self._given[0],
                          input_triangles=self._given[1], patches=list(self.patches))

    def boxes(self) -> tuple:
        """(low, high) corners of the current triangles' boxes, (m, 3) each."""
        return self.box.view()[:, :3], self.box.view()[:, 3:]

    def _near(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        """The triangles whose boxes meet [low, high]."""
        rows = self.index.candidates(low, high, self.triangles.count)
        box = self.box.data[rows]
        return rows[((box[:, 3:] >= low) & (box[:, :3] <= high)).all(axis=1)]

    def remove_handle(self, loop: np.ndarray, tag: int, **options) -> list:
        """``edit.remove_handle(vertices, triangles, loop, **options)`` on the mesh held (loop in
        its ids), done in place; returns the new patches (ids of the mesh held, ``hole=tag``)."""
        vertices, triangles = self.vertices.view(), self.triangles.view()
        points = vertices[loop]
        length = float(np.linalg.norm(points - np.roll(points, -1, axis=0), axis=1).sum())
        for grow in GROWTH:
            low, high = points.min(axis=0) - grow * length, points.max(axis=0) + grow * length
            near = self._near(low, high)
            if len(near) * 2 > len(triangles):
                break
            ids = sorted_unique(triangles[near].reshape(-1))
            self._local[ids] = np.arange(len(ids), dtype=np.int32)  # the rank of each id in ids
            try:
                local = edit.remove_handle(vertices[ids], self._local[triangles[near]], self._local[loop], **options)
            except ValueError as error:
                if "separates" not in str(error):
                    raise
                continue
            if _inside(local, len(ids), len(near), low, high):
                return self._write(ids, near, local, tag, (low, high))
        whole = edit.remove_handle(vertices, triangles, loop, **options)
        return self._write(np.arange(len(vertices)), np.arange(len(triangles)), whole, tag,
                           (np.full(3, -np.inf), np.full(3, np.inf)))

    def _write(self, ids: np.ndarray, near: np.ndarray, local: EditResult, tag: int, inside: tuple) -> list:
        """An edit of the triangles `near` (vertices `ids`) written over them; its new vertices
        and triangles appended, every changed box inside the box ``inside`` (low, high). The edit
        keeps its input's ids and appends (as cuts and fills do)."""
        n, m, n_local, m_local = self.vertices.count, self.triangles.count, len(ids), len(near)
        if not np.array_equal(local.vertex_source[:n_local], np.arange(n_local)) or \
                not np.array_equal(local.face_source[:m_local], np.arange(m_local)):
            raise TopStocError("internal: a clean-up step renumbered the vertices or triangles")
        to_global = np.concatenate([ids, n + np.arange(local.num_vertices - n_local)]).astype(np.int32)
        # A triangle kept with the same corners, none moved, keeps its box: only the others are boxed again.
        stayed = np.zeros(local.num_vertices, dtype=bool)
        stayed[:n_local] = (self.vertices.data[ids] == local.vertices[:n_local]).all(axis=1)
        kept = to_global[local.triangles[:m_local]]
        changed = near[~stayed[local.triangles[:m_local]].all(axis=1) | (kept != self.triangles.data[near]).any(axis=1)]
        self.vertices.data[ids] = local.vertices[:n_local]  # the loop's copies moved
        self.vertices.append(local.vertices[n_local:])
        self.triangles.data[near] = kept
        self.triangles.append(to_global[local.triangles[m_local:]])
        new_source = local.vertex_source[n_local:]
        self.vertex_source.append(through(self.vertex_source.view(), np.where(new_source >= 0, ids[np.maximum(new_source, 0)], -1)))
        self.face_source.append(np.full(local.num_triangles - m_local, -1, dtype=np.int32))
        local_corners = local.corner_source[m_local:]
        corner = np.where(local_corners >= 0, 3 * near[local_corners // 3] + local_corners % 3, -1)
        self.corner_source.append(through(self.corner_source.view().reshape(-1), corner))
        patches = [Patch(hole=tag, boundary=to_global[p.boundary],
                         triangles=slice(m + p.triangles.start - m_local, m + p.triangles.stop - m_local),
                         vertices=slice(n + p.vertices.start - n_local, n + p.vertices.stop - n_local),
                         method=p.method, normal=p.normal, refined=p.refined, faired=p.faired)
                   for p in local.patches]
        self.patches += patches
        if len(self._local) < len(self.vertices.data):  # grown with the vertices' room
            self._local = np.zeros(len(self.vertices.data), dtype=np.int32)
        boxes = _boxes(self.vertices.view(), self.triangles.view()[np.concatenate([changed, np.arange(m, self.triangles.count)])])
        moved = (self.box.data[changed] != boxes[:len(changed)]).any(axis=1)
        self.box.data[changed] = boxes[:len(changed)]
        self.box.append(boxes[len(changed):])
        self.index.record(*inside, np.concatenate([changed[moved], np.arange(m, self.triangles.count)]))
        return patches


def _boxes(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The triangles' bounding boxes, (m, 6): low corner then high corner."""
    a, b, c = (vertices[triangles[:, corner]] for corner in range(3))
    out = np.empty((len(triangles), 6))
    np.minimum(np.minimum(a, b, out=out[:, :3]), c, out=out[:, :3])  # elementwise: a reduce over
    np.maximum(np.maximum(a, b, out=out[:, 3:]), c, out=out[:, 3:])  # the middle axis is slower
    return out


def _inside(local: EditResult, n: int, m: int, low, high) -> bool:
    """Whether every triangle the local edit created or moved lies inside [low, high]."""
    moved = np.zeros(local.num_vertices, dtype=bool)
    moved[n:] = True
    for side in local.cut_sides:
        moved[side.vertices] = True
    changed = moved[local.triangles].any(axis=1)
    corners = local.vertices[local.triangles[changed]]
    return bool(np.all(corners >= low) and np.all(corners <= high))


