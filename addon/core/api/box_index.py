"""Which triangles' bounding boxes meet a box, for a mesh edited in many small places.

A scan of every triangle's box costs the mesh per query; the clean-up asks once per handle.
Here the boxes the mesh started with are bucketed once on a uniform grid (by their low corner,
cells as large as the largest box), and each edit is recorded with the box it stayed inside and
the triangles it changed or added. A query reads the grid cells its box can reach and the
edits whose boxes meet it; the caller filters these candidates with the current boxes, which
gives exactly the triangles a full scan finds (local_edit.LocalEditor).
"""

from __future__ import annotations

import numpy as np

#: Queries reaching more grid columns than this read every triangle instead.
MAX_COLUMNS = 4096


def sorted_unique(values: np.ndarray) -> np.ndarray:
    """np.unique of a 1-D integer array by a sort (numpy's hashing unique is many times slower on
    the few thousand ids of a neighbourhood)."""
    values = np.sort(values)
    return values[np.concatenate([[True], values[1:] != values[:-1]])] if len(values) else values


class BoxIndex:
    """Candidates for "boxes meeting [low, high]" over boxes that change only inside recorded
    edits' boxes (see the module docstring)."""

    def __init__(self, low: np.ndarray, high: np.ndarray):
        self.count = len(low)
        self.edit_box = np.empty((16, 6))  # per recorded edit: low then high, with room to grow
        self.edit_rows = []
        if self.count == 0:
            self.cell = 1.0
            return
        self.origin = low.min(axis=0)
        span = float((high.max(axis=0) - self.origin).max())
        # Cells as large as the largest box (so a box meeting the query has its low corner in
        # a reachable cell), at most 1024 a side (so that cell keys fit any mesh).
        self.cell = max(float((high - low).max()), span / 1024, 1e-300)
        cells = np.floor((low - self.origin) / self.cell).astype(np.int64)
        self.dims = cells.max(axis=0) + 1
        keys = (cells[:, 0] * self.dims[1] + cells[:, 1]) * self.dims[2] + cells[:, 2]
        self.order = np.argsort(keys, kind="stable").astype(np.int64)
        self.keys = keys[self.order]

    def record(self, low: np.ndarray, high: np.ndarray, rows: np.ndarray) -> None:
        """An edit changed or added triangles ``rows``, all with boxes inside [low, high]."""
        if len(self.edit_rows) == len(self.edit_box):
            self.edit_box = np.concatenate([self.edit_box, np.empty_like(self.edit_box)])
        self.edit_box[len(self.edit_rows)] = np.concatenate([low, high])
        self.edit_rows.append(np.asarray(rows, dtype=np.int64))

    def candidates(self, low: np.ndarray, high: np.ndarray, total: int) -> np.ndarray:
        """Sorted triangle ids among ``total`` that may meet [low, high]: a superset of the
        answer (or every id, when the query reaches too much of the grid)."""
        if self.count == 0:
            return self._edited(low, high)
        first = np.floor((low - self.cell - self.origin) / self.cell)
        last = np.floor((high - self.origin) / self.cell)
        first = np.clip(first, 0, self.dims - 1).astype(np.int64)
        last = np.clip(last, -1, self.dims - 1).astype(np.int64)
        if np.any(last < first):  # below the grid: no box the mesh started with
            return self._edited(low, high)
        xs, ys = np.arange(first[0], last[0] + 1), np.arange(first[1], last[1] + 1)
        if len(xs) * len(ys) > MAX_COLUMNS:
            return np.arange(total, dtype=np.int64)
        columns = (xs[:, None] * self.dims[1] + ys[None, :]).reshape(-1) * self.dims[2]
        starts = np.searchsorted(self.keys, columns + first[2], "left")
        stops = np.searchsorted(self.keys, columns + last[2], "right")
        lengths = stops - starts
        offsets = np.repeat(starts - np.concatenate([[0], np.cumsum(lengths)[:-1]]), lengths)
        found = self.order[np.arange(int(lengths.sum()), dtype=np.int64) + offsets]
        return sorted_unique(np.concatenate([found, self._edited(low, high)]))

    def _edited(self, low: np.ndarray, high: np.ndarray) -> np.ndarray:
        """The rows of the recorded edits whose boxes meet [low, high]."""
        if not self.edit_rows:
            return np.zeros(0, dtype=np.int64)
        boxes = self.edit_box[:len(self.edit_rows)]
        meet = np.flatnonzero(np.all(boxes[:, 3:] >= low, axis=1) & np.all(boxes[:, :3] <= high, axis=1))
        return sorted_unique(np.concatenate([self.edit_rows[i] for i in meet])) if len(meet) else \
            np.zeros(0, dtype=np.int64)
