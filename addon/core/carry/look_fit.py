"""The look's values on a decimated mesh fitted to the source's, in the least-squares sense.

Carried values (``attributes.corner_values``) are the source's at each output vertex: exact where
the vertex stands, but an output triangle spans many input triangles, and the linear field
through its corners' source values is not the one closest to the source's field over its area
(a colour band narrower than a triangle is lost or smeared whatever the corner values; the best
corner values lose least). As Hoppe et al. fit scalar attributes of a mesh to points ("Progressive
meshes", 1996, §4.2), the values of each output *wedge* (the corners of one output vertex that
carry the same value: one per side of a UV seam or hard edge, so seams stay seams) are solved for
together, minimising the squared difference between the output's interpolated value and the
source's at matched points, sampled in both directions (points on the source to their closest
point on the output, points on the output to their closest point on the source: what a viewer
sees from either side), each direction weighed by area as a whole; matches far off the fit
(a point sent across a seam to another UV island) are weighed down in two more rounds. A small
pull towards the carried values keeps every wedge determined. A vertex on a UV seam keeps its
UVs (both sides of the seam still meet the same texels; the island outlines stay exact); normals
and colours are fitted on both sides of their hard edges. Normals are fitted per component and
made unit again; UVs and colours stay within the source's range. Deterministic: fixed
quadrature points, no random draw. Used where the look was in the decimation's cost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..support.native import engine

#: Points per direction at most (a larger mesh is sampled on every k-th triangle).
MAX_POINTS = 120_000
#: Sub-triangles per output triangle edge for its quadrature points (s * s points).
MAX_SUBDIVISION = 4
#: Pull towards the carried values, relative to a wedge's own weight from the points.
PULL = 1e-3
#: Conjugate-gradient iterations at most, and the residual reduction that ends them.
MAX_ITERATIONS = 200
TOLERANCE = 1e-8
#: Reweighting rounds against outlying matches, and the scale (times the weighted median miss).
ROBUST_ROUNDS = 2
ROBUST_SCALE = 3.0


def _areas(vertices, triangles) -> np.ndarray:
    p = vertices[triangles]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def _grid_barycentrics(s: int) -> np.ndarray:
    """(s * s, 3) centroids of the s * s sub-triangles of a triangle cut s times along each edge."""
    rows = []
    for i in range(s):
        for j in range(s - i):
            rows.append(((i + 1 / 3), (j + 1 / 3)))            # upright sub-triangle
            if i + j < s - 1:
                rows.append(((i + 2 / 3), (j + 2 / 3)))        # inverted one
    a = np.array(rows) / s
    return np.column_stack([1 - a.sum(axis=1), a])


def _barycentric(points, corners) -> np.ndarray:
    """(k, 3) barycentric coordinates of ``points`` in triangles ``corners`` (k, 3, 3), clamped."""
    a, e0, e1 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    d = points - a
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
    den = d00 * d11 - d01 * d01
    den = np.where(den > 0, den, 1.0)
    w1, w2 = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
    w = np.clip(np.column_stack([1 - w1 - w2, w1, w2]), 0, None)
    return w / np.maximum(w.sum(axis=1, keepdims=True), 1e-300)


@dataclass
class _Rows:
    """Matched points: each row's output triangle and barycentric weights there, the source
    triangle and barycentric weights of its target value, and the row's weight."""
    triangle: np.ndarray        # (r,) output triangle
    weights: np.ndarray         # (r, 3)
    source: np.ndarray          # (r,) source triangle
    source_weights: np.ndarray  # (r, 3)
    row_weight: np.ndarray      # (r,)


@dataclass
class _Wedges:
    """One layer's wedges: each output corner's, a corner of each, and which are free to move
    (1.0) or held at their carried values (0.0: the UVs of a vertex on a UV seam)."""
    corner: np.ndarray  # (3 m_out,) int64
    first: np.ndarray   # (w,) int64
    free: np.ndarray    # (w, 1) float64

    @staticmethod
    def of(out_triangles, carried, held_vertices=None) -> "_Wedges":
        """Corners of one output vertex with equal carried values are one wedge. ``held_vertices``
        (bool per output vertex, or None for none): those and every vertex with several wedges
        keep their carried values."""
        vertex = out_triangles.ravel()
        first, corner = _groups(np.column_stack([vertex.astype(np.float64), carried]))
        wedge_vertex = vertex[first]
        free = np.ones(len(first), dtype=bool)
        if held_vertices is not None:
            free = (np.bincount(wedge_vertex)[wedge_vertex] == 1) & ~held_vertices[wedge_vertex]
        return _Wedges(corner, first, free.astype(np.float64)[:, None])


def _groups(keys) -> tuple:
    """The distinct rows of ``keys`` in lexicographic order: (the first index of each, each
    row's group); as np.unique(axis=0), in half its time (one stable lexsort)."""
    order = np.lexsort(keys.T[::-1])
    ordered = keys[order]
    new = np.ones(len(keys), dtype=bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    group = np.empty(len(keys), dtype=np.int64)
    group[order] = np.cumsum(new) - 1
    return order[new], group


def seam_vertices(triangles, corner_values, count: int) -> np.ndarray:
    """Bool per vertex (``count`` of them): whether its corners carry more than one value."""
    vertex = np.asarray(triangles, dtype=np.int64).ravel()
    values = np.asarray(corner_values, dtype=np.float64).reshape(len(vertex), -1)
    one = np.zeros((count, values.shape[1]))
    one[vertex] = values  # one corner's value per vertex (whichever was written last)
    differs = (values != one[vertex]).any(axis=1)
    return np.bincount(vertex[differs], minlength=count) > 0


class LookFit:
    """Matched points between a source mesh and its decimation, found once and used for every
    corner attribute the decimation carries (``fit``)."""

    def __init__(self, source_vertices, source_triangles, out_vertices, out_triangles, kept=None):
        """``kept``: the input vertex each output vertex stands for (DecimateResult.kept), so that
        a vertex on one of the source's UV seams keeps its UVs even where the output shows one
        side only; None: the output's own seams only."""
        self.source_triangles = np.asarray(source_triangles, dtype=np.int64).reshape(-1, 3)
        self.kept = None if kept is None else np.asarray(kept, dtype=np.int64)
        self.source_count, self.out_count = len(source_vertices), len(out_vertices)
        sv, st = np.asarray(source_vertices, dtype=np.float64), self.source_triangles
        ov = np.asarray(out_vertices, dtype=np.float64)
        self.triangles = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
        ot = self.triangles
        there = self._from_source(sv, st, ov, ot, engine.Surface(ov, ot))
        back = self._from_output(sv, st, ov, ot, engine.Surface(sv, st))
        self.rows = _Rows(*(np.concatenate([a, b]) for a, b in zip(vars(there).values(), vars(back).values())))

    @staticmethod
    def _from_source(sv, st, ov, ot, out_surface) -> _Rows:
        """Three points in each (every k-th) source triangle, matched to the output."""
        step = max(1, -(-3 * len(st) // MAX_POINTS))
        chosen = np.arange(0, len(st), step)
        bary = np.full((3, 3), 1 / 6) + np.eye(3) / 2      # degree-2 quadrature points
        triangle = np.repeat(chosen, 3)
        weights = np.tile(bary, (len(chosen), 1))
        points = np.einsum("kj,kjd->kd", weights, sv[st[triangle]])
        raw = engine.closest_points(out_surface, points)
        near = np.asarray(raw["triangle"], dtype=np.int64)
        near_weights = _barycentric(np.asarray(raw["point"]), ov[ot[near]])
        area = np.repeat(_areas(sv, st[chosen]), 3)
        return _Rows(near, near_weights, triangle, weights, area / max(area.sum(), 1e-300))

    @staticmethod
    def _from_output(sv, st, ov, ot, source_surface) -> _Rows:
        """Points on a grid in each (every k-th) output triangle, matched to the source."""
        s = int(np.clip(np.sqrt(MAX_POINTS / max(len(ot), 1)), 1, MAX_SUBDIVISION))
        bary = _grid_barycentrics(s)
        chosen = np.arange(0, len(ot), max(1, -(-len(ot) // MAX_POINTS)))
        triangle = np.repeat(chosen, len(bary))
        weights = np.tile(bary, (len(chosen), 1))
        points = np.einsum("kj,kjd->kd", weights, ov[ot[triangle]])
        raw = engine.closest_points(source_surface, points)
        near = np.asarray(raw["triangle"], dtype=np.int64)
        near_weights = _barycentric(np.asarray(raw["point"]), sv[st[near]])
        area = np.repeat(_areas(ov, ot[chosen]), len(bary))
        return _Rows(triangle, weights, near, near_weights, area / max(area.sum(), 1e-300))

    def fit(self, source_values, carried, kind: str) -> np.ndarray:
        """Fitted values per output corner (3 m_out, k) for per-source-corner ``source_values``
        (m, 3, k) whose carried values are ``carried`` (3 m_out, k); the wedges are where the
        carried values split. ``kind``: "uv", "color" or "normal" (unit vectors: target values
        renormalised, results made unit); UVs and colours are clamped into the source's range
        per channel (a colour stays a colour, a UV within its map's extent)."""
        rows = self.rows
        source_values = np.asarray(source_values, dtype=np.float64)
        carried = np.asarray(carried, dtype=np.float64).reshape(3 * len(self.triangles), -1)
        unit = kind == "normal"
        held = None
        if kind == "uv":
            held = np.zeros(self.out_count, dtype=bool)
            if self.kept is not None:
                held = seam_vertices(self.source_triangles, source_values, self.source_count)[self.kept]
        wedges = _Wedges.of(self.triangles, carried, held)
        row_wedges = wedges.corner.reshape(-1, 3)[rows.triangle]
        target = np.einsum("rj,rjk->rk", rows.source_weights, source_values[rows.source])
        if unit:
            target /= np.maximum(np.linalg.norm(target, axis=1, keepdims=True), 1e-300)
        start = carried[wedges.first]
        system = _System(row_wedges, rows.weights, len(start))
        x = system.solve(rows.row_weight, target, start, start, wedges.free)
        for _ in range(ROBUST_ROUNDS):
            # rows matched across a seam (another UV island) or a fold pull far: weigh them down
            miss = np.linalg.norm(np.einsum("rj,rjk->rk", rows.weights, x[row_wedges]) - target, axis=1)
            order = np.argsort(miss)
            half = np.searchsorted(np.cumsum(rows.row_weight[order]), 0.5 * rows.row_weight.sum())
            scale = ROBUST_SCALE * max(miss[order][min(half, len(order) - 1)], 1e-12)
            x = system.solve(rows.row_weight / (1 + (miss / scale) ** 2), target, x, start, wedges.free)
        out = x[wedges.corner]
        if unit:
            length = np.linalg.norm(out, axis=1, keepdims=True)
            out = np.where(length > 0, out / np.where(length > 0, length, 1.0), carried)
        else:
            flat = source_values.reshape(-1, source_values.shape[-1])
            out = np.clip(out, flat.min(axis=0), flat.max(axis=0))
        return out


class _System:
    """The normal equations of the least squares over the rows' wedges, sparse: the pattern of
    wedge pairs found once per layer, the values for each set of row weights (``solve``)."""

    def __init__(self, wedges, weights, n: int):
        self.wedges, self.weights, self.n = wedges, weights, n
        pairs, entry = np.unique((np.repeat(wedges, 3, axis=1) * n + np.tile(wedges, 3)).ravel(), return_inverse=True)
        self.entry, self.i, self.j = entry.ravel(), pairs // n, pairs % n
        self.products = np.repeat(weights, 3, axis=1) * np.tile(weights, 3)  # (r, 9)

    def _gather(self, values) -> np.ndarray:
        """Per wedge, the sum of ``values`` (r, 3, k) over the rows' corners."""
        flat = self.wedges.ravel()
        return np.stack([np.bincount(flat, weights=values[:, :, c].ravel(), minlength=self.n)
                         for c in range(values.shape[2])], axis=1)

    def solve(self, w, target, guess, start, free) -> np.ndarray:
        """The wedge values minimising sum_r w_r |sum_j weights_rj x[wedges_rj] - target_r|^2
        plus the pull to ``start``, the ``free`` ones only (the others stay at ``guess``), by
        Jacobi-preconditioned conjugate gradients from ``guess`` (one per channel, side by side)."""
        n = self.n
        values = np.bincount(self.entry, weights=(self.products * w[:, None]).ravel(), minlength=len(self.i))
        on_diagonal = self.i == self.j
        diagonal = np.bincount(self.i[on_diagonal], weights=values[on_diagonal], minlength=n)
        pull = (PULL * diagonal + 1e-9 * max(diagonal.mean(), 1e-300))[:, None]  # each wedge's own scale
        diagonal = diagonal[:, None] + pull

        def normal(x):  # (B^T W B + pull) x
            return np.stack([np.bincount(self.i, weights=values * x[self.j, c], minlength=n)
                             for c in range(x.shape[1])], axis=1) + pull * x

        rhs = self._gather((self.weights * w[:, None])[:, :, None] * target[:, None, :]) + pull * start
        x = guess.copy()
        r = (rhs - normal(x)) * free
        z = r / diagonal
        p = z.copy()
        rz = (r * z).sum(axis=0)
        bound = TOLERANCE * np.maximum((rhs * rhs).sum(axis=0), 1e-300)
        for _ in range(MAX_ITERATIONS):
            if np.all((r * r).sum(axis=0) <= bound):
                break
            q = normal(p) * free
            pq = (p * q).sum(axis=0)
            alpha = rz / np.where(pq > 0, pq, 1.0)
            x += alpha * p
            r -= alpha * q
            z = r / diagonal
            rz_next = (r * z).sum(axis=0)
            p = z + (rz_next / np.where(rz > 0, rz, 1.0)) * p
            rz = rz_next
        return x


def fit_look(source_vertices, source_triangles, out_vertices, out_triangles, layers: dict, kept=None) -> dict:
    """``layers`` {name: (source values per input triangle corner (m, 3, k), carried values per
    output corner (3 m_out, k), kind)} fitted on one set of matched points (LookFit), each on its
    own wedges (LookFit.fit): {name: fitted values per output corner}. ``kept``: as LookFit's."""
    out_triangles = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
    carried = {name: np.asarray(c, dtype=np.float64).reshape(3 * len(out_triangles), -1)
               for name, (_, c, _) in layers.items()}
    if not layers or len(out_triangles) == 0:
        return carried
    fit = LookFit(source_vertices, source_triangles, out_vertices, out_triangles, kept)
    fitted = {}
    for name, (source, _, kind) in layers.items():
        fitted[name] = fit.fit(source, carried[name], kind)
    return fitted


def vertex_means(corner_values, out_triangles, count: int) -> np.ndarray:
    """Per output vertex, the mean of its corners' ``corner_values`` (3 m_out, k): a fitted
    per-vertex layer (a point colour) back on its domain."""
    vertex = np.asarray(out_triangles, dtype=np.int64).ravel()
    values = np.asarray(corner_values, dtype=np.float64)
    uses = np.maximum(np.bincount(vertex, minlength=count), 1)
    means = np.stack([np.bincount(vertex, weights=values[:, c], minlength=count) / uses
                      for c in range(values.shape[1])], axis=1)
    # a mean may round an ulp past its largest term: kept within the corners' range, so a colour
    # clamped to the source's stays in it
    return np.clip(means, values.min(axis=0), values.max(axis=0)) if len(values) else means
