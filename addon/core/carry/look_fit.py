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
sees from either side), each direction weighed by area as a whole. A small pull towards the
carried values keeps every wedge determined. Normals are fitted per component and made unit
again; colours are clamped into [0, 1]. Deterministic: fixed quadrature points, no random draw.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..support.native import engine

#: Points per direction at most (a larger mesh is sampled on every k-th triangle).
MAX_POINTS = 120_000
#: Sub-triangles per output triangle edge for its quadrature points (s * s points).
MAX_SUBDIVISION = 4
#: Pull towards the carried values, relative to a wedge's mean weight from the points.
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
    """Matched points: each row's three output wedges and weights, the source triangle and
    barycentric weights of its target value, and the row's weight."""
    wedges: np.ndarray        # (r, 3) int64
    weights: np.ndarray       # (r, 3)
    source: np.ndarray        # (r,) source triangle
    source_weights: np.ndarray  # (r, 3)
    row_weight: np.ndarray    # (r,)


class LookFit:
    """Matched points between a source mesh and its decimation, built once and used for every
    corner attribute the decimation carries (``fit``)."""

    def __init__(self, source_vertices, source_triangles, out_vertices, out_triangles, wedge_keys):
        """``wedge_keys`` (3 m_out, j): per output corner, values that tell its wedge apart (the
        carried values of the attributes that split at seams); corners of one output vertex with
        equal keys are one wedge."""
        sv = np.asarray(source_vertices, dtype=np.float64)
        st = np.asarray(source_triangles, dtype=np.int64).reshape(-1, 3)
        ov = np.asarray(out_vertices, dtype=np.float64)
        ot = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
        keys = np.column_stack([ot.reshape(-1, 1).astype(np.float64), np.asarray(wedge_keys, dtype=np.float64)])
        _, first, self.corner_wedge = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        self.corner_wedge = self.corner_wedge.ravel()
        self.first_corner = first  # a corner of each wedge
        self.count = len(first)
        out_wedges = self.corner_wedge.reshape(-1, 3)
        source_surface = engine.Surface(sv, st)
        out_surface = engine.Surface(ov, ot)
        self.rows = self._from_source(sv, st, ov, ot, out_wedges, out_surface)
        there = self._from_output(sv, st, ov, ot, out_wedges, source_surface)
        self.rows = _Rows(*(np.concatenate([a, b]) for a, b in zip(vars(self.rows).values(), vars(there).values())))

    @staticmethod
    def _from_source(sv, st, ov, ot, out_wedges, out_surface) -> _Rows:
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
        area = _areas(sv, st)[triangle]
        return _Rows(out_wedges[near], near_weights, triangle, weights, area / max(area.sum(), 1e-300))

    @staticmethod
    def _from_output(sv, st, ov, ot, out_wedges, source_surface) -> _Rows:
        """Points on a grid in each output triangle, matched to the source."""
        s = int(np.clip(np.sqrt(MAX_POINTS / max(len(ot), 1)), 1, MAX_SUBDIVISION))
        bary = _grid_barycentrics(s)
        triangle = np.repeat(np.arange(len(ot)), len(bary))
        weights = np.tile(bary, (len(ot), 1))
        points = np.einsum("kj,kjd->kd", weights, ov[ot[triangle]])
        raw = engine.closest_points(source_surface, points)
        near = np.asarray(raw["triangle"], dtype=np.int64)
        near_weights = _barycentric(np.asarray(raw["point"]), sv[st[near]])
        area = _areas(ov, ot)[triangle]
        return _Rows(out_wedges[triangle], weights, near, near_weights, area / max(area.sum(), 1e-300))

    def fit(self, source_values, carried, unit: bool = False, limits=None) -> np.ndarray:
        """Fitted values per output corner (3 m_out, k) for per-source-corner ``source_values``
        (m, 3, k) whose carried values are ``carried`` (3 m_out, k). ``unit``: normals (target
        values renormalised, results made unit); ``limits``: (low, high) to clamp into."""
        rows = self.rows
        source_values = np.asarray(source_values, dtype=np.float64)
        carried = np.asarray(carried, dtype=np.float64).reshape(len(self.corner_wedge), -1)
        target = np.einsum("rj,rjk->rk", rows.source_weights, source_values[rows.source])
        if unit:
            target /= np.maximum(np.linalg.norm(target, axis=1, keepdims=True), 1e-300)
        start = carried[self.first_corner]
        row_weight = self.rows.row_weight
        x = self._solve(target, start, row_weight)
        for _ in range(ROBUST_ROUNDS):
            # rows matched across a seam (another UV island) or a fold pull far: weigh them down
            miss = np.linalg.norm(np.einsum("rj,rjk->rk", rows.weights, x[rows.wedges]) - target, axis=1)
            order = np.argsort(miss)
            median = miss[order][np.searchsorted(np.cumsum(row_weight[order]), 0.5 * row_weight.sum())
                                 .clip(0, len(order) - 1)]
            scale = ROBUST_SCALE * max(median, 1e-12)
            x = self._solve(target, x, row_weight / (1 + (miss / scale) ** 2), start)
        out = x[self.corner_wedge]
        if unit:
            length = np.linalg.norm(out, axis=1, keepdims=True)
            out = np.where(length > 0, out / np.where(length > 0, length, 1.0), carried)
        if limits is not None:
            out = np.clip(out, *limits)
        return out

    def _solve(self, target, guess, w, start=None) -> np.ndarray:
        """Least squares over the rows plus the pull to ``start``, by Jacobi-preconditioned
        conjugate gradients (one per channel, run side by side)."""
        rows, n = self.rows, self.count
        start = guess if start is None else start
        flat_wedges = rows.wedges.ravel()

        def apply_rows(x):      # B x: each row's interpolated value
            return np.einsum("rj,rjk->rk", rows.weights, x[rows.wedges])

        def apply_transpose(y):  # B^T (w y)
            weighted = (rows.weights * w[:, None])[:, :, None] * y[:, None, :]
            return np.stack([np.bincount(flat_wedges, weights=weighted[:, :, c].ravel(), minlength=n)
                             for c in range(y.shape[1])], axis=1)

        diagonal = np.bincount(flat_wedges, weights=(rows.weights ** 2 * w[:, None]).ravel(), minlength=n)
        pull = PULL * max(diagonal.mean(), 1e-300)
        diagonal = diagonal + pull

        def normal(x):
            return apply_transpose(apply_rows(x)) + pull * x

        rhs = apply_transpose(target) + pull * start
        x = guess.copy()
        r = rhs - normal(x)
        z = r / diagonal[:, None]
        p = z.copy()
        rz = (r * z).sum(axis=0)
        bound = TOLERANCE * np.maximum((rhs * rhs).sum(axis=0), 1e-300)
        for _ in range(MAX_ITERATIONS):
            if np.all((r * r).sum(axis=0) <= bound):
                break
            q = normal(p)
            alpha = rz / np.where((p * q).sum(axis=0) > 0, (p * q).sum(axis=0), 1.0)
            x += alpha * p
            r -= alpha * q
            z = r / diagonal[:, None]
            rz_next = (r * z).sum(axis=0)
            p = z + (rz_next / np.where(rz > 0, rz, 1.0)) * p
            rz = rz_next
        return x


def fit_look(source_vertices, source_triangles, out_vertices, out_triangles, layers: dict) -> dict:
    """``layers`` {name: (source values per input triangle corner (m, 3, k), carried values per
    output corner (3 m_out, k), unit)} fitted together (one LookFit: the wedges split where any
    layer's carried values do): {name: fitted values per output corner}. ``unit`` layers are
    normals; the others are clamped into their source's range per channel (a colour stays a
    colour, a UV within its map's extent)."""
    out_triangles = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
    carried = {name: np.asarray(c, dtype=np.float64).reshape(3 * len(out_triangles), -1)
               for name, (_, c, _) in layers.items()}
    if not layers or len(out_triangles) == 0:
        return carried
    keys = np.concatenate(list(carried.values()), axis=1)
    fit = LookFit(source_vertices, source_triangles, out_vertices, out_triangles, keys)
    fitted = {}
    for name, (source, _, unit) in layers.items():
        source = np.asarray(source, dtype=np.float64)
        k = source.shape[-1]
        limits = None if unit else (source.reshape(-1, k).min(axis=0), source.reshape(-1, k).max(axis=0))
        fitted[name] = fit.fit(source, carried[name], unit=unit, limits=limits)
    return fitted


def vertex_means(corner_values, out_triangles, count: int) -> np.ndarray:
    """Per output vertex, the mean of its corners' ``corner_values`` (3 m_out, k): a fitted
    per-vertex layer (a point colour) back on its domain."""
    vertex = np.asarray(out_triangles, dtype=np.int64).ravel()
    values = np.asarray(corner_values, dtype=np.float64)
    uses = np.maximum(np.bincount(vertex, minlength=count), 1)
    return np.stack([np.bincount(vertex, weights=values[:, c], minlength=count) / uses
                     for c in range(values.shape[1])], axis=1)
