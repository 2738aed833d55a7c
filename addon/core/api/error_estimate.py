"""A bounded estimate of the symmetric Hausdorff max (docs/design.md §3.1): cheap enough to report for
every output of a batch and to guide an error-bounded search, with a guaranteed bracket.

>>> bound = estimate_error(original, decimated)
>>> bound.estimate <= exact maximum <= bound.upper

For a big original (QUICK_TRIANGLES or more) by default, the engine's quick bound
(``quick_hausdorff_bound``, native/src/distance/quick_bound.cpp), which builds no search
structure over the original's triangles: the original's vertices are grouped by the cells of a
grid, one per cell measured against the result's BVH and the others against the triangle found
for it (any triangle of the result bounds the distance from above); a triangle of the original
is bounded by its corners (the distance to one triangle is convex; the distance to a surface is
1-Lipschitz); the corners of those whose bound exceeds ``(1 + gap)`` times the largest distance
measured are measured exactly, and the few still above it bracketed exactly. The result's triangles are split until the distance to the original's
triangles around a nearby vertex, plus the piece's reach, is within ``(1 + gap)`` of the largest
such value; the points with the 16 largest are measured exactly. Where a side's bound is still
above ``(1 + gap)`` times the estimate (a tiny maximum against long sides: a result nearly on the
original), that side is bracketed too by a walk down its surface's BVH (``bracket_one_sided_max``,
which opens only the boxes that may hide a larger distance) until it converges, and the tighter
bounds kept.
``estimate`` is the largest distance measured exactly (attained, so never above the exact
maximum); ``upper`` the largest bound (no point is farther). ``mean`` estimates the mean
distance from the original (one measured vertex per grid cell, unweighted).

Otherwise both sides are bracketed at once (``bracket_symmetric_max``, on two threads): every
vertex of a side's surface is measured (most by a walk over the other surface from a
neighbour's triangle, the rest looked up, those that may hold the largest distance among them),
then its triangles are bounded by their corners (the
distance is 1-Lipschitz; the distance to one triangle of the other surface is convex) and by the
other surface's triangles beneath them (distance/projected_bound.cpp), and only those whose bound
exceeds ``(1 + gap)`` times the largest distance found are split and measured again, until none
is left, or all are under RESOLUTION times the larger diagonal (``converged``), or ``queries``
closest-point queries a side were spent (default: the exact measurement's budget, which the
originals tried never reach; then the bracket holds, only wider). ``exact_error`` asks for the
gap, floor and query budget of the exact bracketed maximum of hausdorff.py. ``decide_error``
asks only whether the maximum exceeds a bound (the error-bounded search's exact check);
``SampledError`` is the search's cheap estimate (distances attained at points spread on both
surfaces, no upper bound).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .hausdorff import as_surface
from ..support.native import engine

DEFAULT_GAP = 0.25         #: relative gap aimed at between the estimate and its upper bound, by default
#: originals of this many triangles or more get the quick bound by default: building their BVH and
#: measuring all their vertices costs more than the decimation (smaller ones settle in fewer queries)
QUICK_TRIANGLES = 250_000
#: a bound under this share of the larger diagonal counts as settled: a result lying on its original
#: up to rounding (float32 coordinates, as most mesh files store them, round at 6e-8 of their size)
#: is not split down to that rounding
RESOLUTION = 1e-7
EXACT_GAP = 1e-3           #: the gap of the exact bracketed maximum (hausdorff.py's max_tolerance)
EXACT_RESOLUTION = 1e-13   #: the exact one's floor (the engine's own)
EXACT_QUERIES = 20_000_000 #: closest-point queries per side for the exact one
#: SampledError deciding a bound measures its points in chunks of this many and stops at the
#: first chunk with one beyond it (a failing result is often found in the first chunks)
VERDICT_CHUNK = 8192


@dataclass(frozen=True)
class ErrorBound:
    """estimate <= exact symmetric Hausdorff max <= upper (absolute, units of the mesh)."""

    estimate: float
    upper: float
    forward: tuple      #: (estimate, upper) from the original to the result
    backward: tuple     #: (estimate, upper) from the result to the original
    gap: float          #: the relative gap asked for
    queries: int        #: closest-point queries made
    converged: bool     #: upper <= estimate * (1 + gap), or upper under the resolution (see RESOLUTION)
    witness: object = None  #: decide_error: a point of the original farther than the bound from the result
    result_witness: object = None  #: decide_error: a point of the result farther than the bound from the original
    mean: float = float("nan")  #: the quick bound's estimate of the mean distance from the original

    @property
    def exact(self) -> bool:
        """True when the bracket is as tight as the exact measurement's."""
        return self.gap <= EXACT_GAP

    def as_dict(self) -> dict:
        return {"estimate": self.estimate, "upper": self.upper, "gap": self.gap, "converged": self.converged,
                "kind": "exact" if self.exact else "estimate"}


def estimate_error(original, result, gap: float = DEFAULT_GAP, queries=None, *,
                   original_surface=None, quick=None, resolution: float = RESOLUTION) -> ErrorBound:
    """Brackets the symmetric Hausdorff max between ``original`` and ``result`` (each
    ``(vertices, triangles)``, an object with both, or an engine Surface) within the relative
    ``gap``: by the quick bound (``quick`` True; by default when the original has QUICK_TRIANGLES
    triangles or more and no ``queries`` are given), else from both surfaces' vertices with at most
    ``queries`` closest-point queries per side after them (default: EXACT_QUERIES); bounds under
    ``resolution`` times the larger diagonal count as settled.
    original_surface: the original's engine Surface when the caller keeps one for several results."""
    a = original_surface or as_surface(original, "original")
    b = as_surface(result, "result")
    floor = resolution * max(a.diagonal, b.diagonal)
    if quick is None:
        quick = queries is None and a.num_triangles >= QUICK_TRIANGLES
    if quick:
        found = engine.quick_hausdorff_bound(a, b, tolerance=float(gap), resolution=float(resolution))
        sides = [[found["forward_lower"], found["forward_upper"]], [found["backward_lower"], found["backward_upper"]]]
        queries = found["queries"] + found["grid_queries"]
        estimate = max(sides[0][0], sides[1][0])
        for side, (x, y) in zip(sides, ((a, b), (b, a))):
            if side[1] > max(estimate * (1 + gap), floor):  # not settled (a tiny max, long sides): the walk too
                walk = engine.bracket_one_sided_max(x, y, tolerance=gap, max_queries=EXACT_QUERIES)
                side[0], side[1] = max(side[0], walk["lower"]), min(side[1], walk["upper"])  # both hold
                queries += walk["queries"]
        estimate, upper = max(sides[0][0], sides[1][0]), max(sides[0][1], sides[1][1])
        return ErrorBound(estimate=estimate, upper=upper, forward=tuple(sides[0]), backward=tuple(sides[1]),
                          gap=float(gap), queries=int(queries),
                          converged=bool(upper <= max(estimate * (1 + gap), floor)), mean=float(found["forward_mean"]))
    queries = EXACT_QUERIES if queries is None else queries
    found = engine.bracket_symmetric_max(a, b, tolerance=float(gap), resolution=float(resolution),
                                         max_queries=int(queries))
    forward, backward = found["forward"], found["backward"]
    if not (forward["converged"] and backward["converged"]):  # the budget ran out: add spread samples
        forward["lower"] = max(forward["lower"], _sampled_max(original, b, 2 * queries))
        backward["lower"] = max(backward["lower"], _sampled_max(result, a, 2 * queries))
    estimate, upper = max(forward["lower"], backward["lower"]), max(forward["upper"], backward["upper"])
    return ErrorBound(estimate=estimate, upper=upper,
                      forward=(forward["lower"], forward["upper"]), backward=(backward["lower"], backward["upper"]),
                      gap=float(gap), queries=int(forward["queries"] + backward["queries"]),
                      converged=bool(upper <= max(estimate * (1 + gap), floor)))


def exact_error(original, result, *, original_surface=None) -> ErrorBound:
    """The exact bracketed maximum (hausdorff.py's, relative gap 1e-3)."""
    return estimate_error(original, result, EXACT_GAP, EXACT_QUERIES, original_surface=original_surface,
                          resolution=EXACT_RESOLUTION)


def _sampled_max(mesh, other, count: int) -> float:
    """Largest distance to ``other`` among about ``count`` points spread over ``mesh`` (every
    k-th triangle's centroid and edge midpoints, in the mesh's own order): attained, so a lower
    bound of the max."""
    vertices, triangles = _arrays(mesh)
    step = max(1, -(-3 * len(triangles) // max(1, int(count))))
    corners = vertices[triangles[::step]]
    points = np.concatenate([corners.mean(axis=1), 0.5 * (corners[:, 0] + corners[:, 1]),
                             0.5 * (corners[:, 1] + corners[:, 2])])
    return float(engine.closest_points(other, points)["distance"].max(initial=0.0))


def decide_error(original, result, bound: float, *, original_surface=None) -> ErrorBound:
    """Whether the symmetric Hausdorff max exceeds ``bound``, decided exactly but no tighter than
    that needs: the walk settles every box and piece whose bound is within ``bound`` and stops at
    the first distance above it. Within the bound when ``upper <= bound`` (guaranteed), above it
    when ``estimate > bound`` (attained); a max within the exact gap of the bound counts as above."""
    a = original_surface or as_surface(original, "original")
    b = as_surface(result, "result")
    sides = []
    for x, y in ((a, b), (b, a)):
        side = engine.bracket_one_sided_max(x, y, tolerance=EXACT_GAP, max_queries=EXACT_QUERIES, threshold=bound)
        sides.append(side)
        if side["lower"] > bound:  # decided: above
            break
    forward = (sides[0]["lower"], sides[0]["upper"])
    backward = (sides[1]["lower"], sides[1]["upper"]) if len(sides) > 1 else (0.0, float("inf"))
    witness = sides[0]["lower_point"] if sides[0]["lower"] > bound else None
    result_witness = sides[1]["lower_point"] if len(sides) > 1 and sides[1]["lower"] > bound else None
    return ErrorBound(witness=witness, result_witness=result_witness, estimate=max(forward[0], backward[0]), upper=max(forward[1], backward[1]),
                      forward=forward, backward=backward, gap=EXACT_GAP,
                      queries=int(sum(side["queries"] for side in sides)),
                      converged=all(side["converged"] or side["lower"] > bound for side in sides))


class SampledError:
    """The largest distance over points spread on both surfaces, for many results of one original:
    attained, so never above the exact maximum (a lower bound, not a bracket). The original's
    points (every k-th triangle's centroid and vertex, about ``samples`` in all) are taken once;
    on a result: its vertices, every k-th triangle's centroid and edge midpoint, and its closest
    point to each place where an earlier result was found too far (add_result_witness). With
    ``within`` (deciding a bound only), a point within it of the other surface stops at the first
    triangle found that close, and the first chunk of points with one beyond ``within`` ends the
    measure: the value is then a distance attained above ``within`` (at most the sampled max), or
    at most ``within`` (no smaller than the sampled max) when none is beyond it; the same verdict
    for much fewer triangles visited and, on a failing result, fewer points."""

    def __init__(self, original, original_surface, samples: int = 40_000):
        vertices, triangles = _arrays(original)
        step = max(1, -(-len(triangles) // max(1, samples // 2)))
        points = np.concatenate([vertices[triangles[::step]].mean(axis=1), vertices[triangles[::step, 0]]])
        self.points = points[_z_order(points)]  # neighbours in turn: each query's hint is close
        self.spread = len(self.points)  # the spread points; the witnesses follow (add_witness)
        self.surface, self.samples = original_surface, samples
        self.result_witnesses = np.empty((0, 3))

    def add_witness(self, point) -> None:
        """Measures this point of the original from now on (one an exact check found too far)."""
        self.points = np.concatenate([self.points, np.asarray(point, dtype=np.float64).reshape(1, 3)])

    def add_result_witness(self, point) -> None:
        """From now on measures each result's closest point to this one (a point of an earlier
        result an exact check found too far from the original): the results of nearby counts
        tend to keep the same bulge, which the spread points can miss."""
        self.result_witnesses = np.concatenate([self.result_witnesses, np.asarray(point, dtype=np.float64).reshape(1, 3)])

    def __call__(self, result, within=None, exact_above=None) -> float:
        """The sampled max; with ``within``, only the verdict against it (class docs). exact_above
        (without within): points that close stop at the first triangle found that close, which
        leaves the value exact when it is above exact_above; the rare result whose value is not is
        measured again in full (the same value either way, for fewer triangles visited)."""
        vertices, triangles = _arrays(result)
        step = max(1, -(-len(triangles) // max(1, self.samples // 2)))
        corners = vertices[triangles[::step]]
        surface = as_surface(result, "result")
        near = engine.closest_points(surface, self.result_witnesses)["point"] if len(self.result_witnesses) else np.empty((0, 3))
        points = np.concatenate([vertices, corners.mean(axis=1), 0.5 * (corners[:, 0] + corners[:, 1]), near])
        if within is not None:
            return self._verdict(surface, points, len(near), within)
        largest = self._largest(surface, points, exact_above)
        return self._largest(surface, points) if exact_above is not None and largest <= exact_above else largest

    def _largest(self, surface, points: np.ndarray, within=None) -> float:
        forward = engine.closest_points(surface, self.points, within)["distance"]
        backward = engine.closest_points(self.surface, points, within)["distance"]
        return float(max(forward.max(initial=0.0), backward.max(initial=0.0)))

    def _verdict(self, surface, points: np.ndarray, witnessed: int, within: float) -> float:
        """The points measured with ``within`` in chunks, the places found too far before
        (the last ``witnessed`` of ``points``, the original's points added after the first
        ``spread``) first; the first chunk with a point beyond ``within`` ends it: the value is then
        a distance attained there (above within: the same verdict as all points, fewer measured)."""
        spread = self.spread
        chunks = [(surface, self.points[spread:]), (self.surface, points[len(points) - witnessed:])]
        rest = len(points) - witnessed
        for start in range(0, max(spread, rest), VERDICT_CHUNK):
            chunks += [(surface, self.points[start:min(start + VERDICT_CHUNK, spread)]),
                       (self.surface, points[start:min(start + VERDICT_CHUNK, rest)])]
        largest = 0.0
        for other, chunk in chunks:
            if len(chunk):
                largest = max(largest, float(engine.closest_points(other, chunk, within)["distance"].max()))
                if largest > within:
                    break
        return largest


def _z_order(points: np.ndarray) -> np.ndarray:
    """The order of ``points`` along a Z-order curve of their box (10 bits per axis), so that
    consecutive closest-point queries land near one another (the engine seeds each with the last hit)."""
    if len(points) == 0:
        return np.arange(0)
    low, extent = points.min(axis=0), float(np.ptp(points, axis=0).max())
    cells = ((points - low) / max(extent, 1e-300) * 1023).astype(np.uint64)
    key = np.zeros(len(points), dtype=np.uint64)
    for bit in range(10):
        for axis in range(3):
            key |= ((cells[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(3 * bit + axis)
    return np.argsort(key, kind="stable")


def _arrays(mesh):
    vertices, triangles = mesh if isinstance(mesh, tuple) else (mesh.vertices, mesh.triangles)
    return np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
