"""Error-bounded decimation (docs/design.md §2.11): the fewest vertices whose symmetric Hausdorff error stays
under a bound.

A re-decimation of a prepared mesh costs milliseconds, so the search simply tries vertex
targets: it brackets the answer by factors of four, then bisects (geometrically) until the
smallest passing target and the largest failing one are within the resolution. Every probe
uses the same seed and the original's one measurement surface (its closest-point index built
once), so the search is reproducible. The search runs on a cheap estimate first: the largest
distance over about 40,000 points spread on both surfaces (attained, so a probe above the bound
fails for certain). Only the answer is then checked exactly
(topstoc.core.error_estimate.decide_error: the guaranteed bracket of the exact maximum, refined
only as far as deciding the bound needs). Should it fail, the point it found too far joins the
estimate's points and the search goes on above it. Error need not fall monotonically with the vertex count (each count draws other
samples); the guarantee is the one the search can check: the returned decimation's error is
within the bound (a guaranteed upper bound of its exact maximum), and the target
``resolution`` below it (``failed_target``) measured a distance above the bound. ``progress(probe, target, vertices, error, passed)``, when given, is called after every
probe; returning False stops the search with ``Cancelled``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

from .error_estimate import SampledError, decide_error
from .hausdorff import as_surface
from ..support import params
from ..support.native import engine
from ..support.errors import TopStocError

Cancelled = engine.Cancelled

@dataclass(frozen=True)
class ErrorBoundReport:
    """How the error-bounded search went. Errors are absolute (same units as the mesh)."""

    max_error: float            #: the bound, absolute
    achieved_error: float       #: guaranteed upper bound of the returned decimation's symmetric Hausdorff max
    target_vertices: int        #: vertex target of the returned decimation
    output_vertices: int        #: vertices it has (repairs may add a few)
    failed_target: int          #: largest probed target above the bound (0: none below)
    failed_error: float         #: a distance attained by it, above the bound (inf when failed_target is 0)
    resolution: int             #: failed_target and target_vertices are at most this far apart
    probes: list = field(default_factory=list)  #: (target, output vertices, error) per probe, in order
    queries: int = 0            #: closest-point queries of all probes
    seconds: float = 0.0


def resolution_count(target: int, resolution: float) -> int:
    """Vertex-count resolution at ``target`` for a relative resolution."""
    return max(1, int(math.floor(resolution * target)))


class _Probes:
    """The probes of one search: each target decimated once and judged, by the sampled estimate
    or exactly (see the module docs)."""

    def __init__(self, mesh, original, bound: float, decimate_at: Callable[[int], object], progress):
        self.mesh, self.original, self.sampled = mesh, original, SampledError(mesh, original)
        self.bound, self.decimate_at, self.progress = bound, decimate_at, progress
        self.probes, self.results, self.exact, self.queries = [], {}, set(), 0

    def __call__(self, n: int, exact: bool = False) -> bool:
        """Decimates at n (once), records (result, error); True when within the bound."""
        result = self.results[n][0] if n in self.results else self.decimate_at(n)
        if exact:
            decided = decide_error(self.mesh, result, self.bound, original_surface=self.original)
            self.queries += decided.queries
            self.exact.add(n)
            passed = decided.upper <= self.bound
            error = decided.upper if passed else decided.estimate
            if decided.witness is not None:
                self.sampled.add_witness(decided.witness)
        else:
            error = self.sampled(result)
            passed = error <= self.bound
        self.probes.append((n, result.num_vertices, error))
        self.results[n] = (result, error, passed)
        if self.progress is not None and self.progress(len(self.probes), n, result.num_vertices, error, passed) is False:
            raise Cancelled("the error-bounded search was cancelled")
        return passed


def _bisect(probe: _Probes, lo: int, hi: int, resolution: float, exact: bool) -> tuple:
    """Narrows (lo fails, hi passes) until within the resolution."""
    while hi - lo > resolution_count(hi, resolution):
        mid = int(round(math.sqrt(lo * hi))) if lo > 0 else hi // 2
        mid = min(max(mid, lo + 1), hi - 1)
        if probe(mid, exact):
            hi = mid
        else:
            lo = mid
    return lo, hi


def search_vertex_count(mesh, max_error: float, decimate_at: Callable[[int], object], *,
                        relative: bool = False, resolution: float = 0.01, progress=None):
    """Finds the smallest vertex target whose decimation has symmetric error <= max_error.

    mesh: the prepared topstoc.Mesh; decimate_at(n): its decimation with n target vertices
    (fixed seed and options). relative: max_error is a fraction of the bounding-box diagonal
    (0.01 = 1 %). resolution: stop when the failing and passing targets differ by at most
    ``max(1, resolution * target)``. progress: ``progress(probe, target, vertices, error,
    passed)`` after every probe; False stops the search with ``Cancelled``.
    Returns (DecimateResult, ErrorBoundReport).
    """
    max_error = params.number("max_error", max_error, 0)
    resolution = params.number("resolution", resolution, 0, 1, high_open=True)
    started = time.perf_counter()
    original = as_surface(mesh, "mesh")
    bound = max_error * original.diagonal if relative else float(max_error)
    report = mesh.report()
    active = report.input_vertices - report.isolated_vertices
    probe = _Probes(mesh, original, bound, decimate_at, progress)

    # Bracket: lo fails (0 = nothing below tried), hi passes (the full vertex count always does:
    # its decimation is the input itself).
    lo, hi = 0, active
    n = min(active, max(4, active // 64))
    if probe(n):
        hi = n
        while hi > 4:
            n = max(1, hi // 4)
            if probe(n):
                hi = n
            else:
                lo = n
                break
    else:
        lo = n
        while True:
            n = min(active, 4 * lo)
            if n == active:
                break
            if probe(n):
                hi = n
                break
            lo = n
    # The estimate passes hi: check it exactly. Should the check fail, its far point joins the
    # estimate's points, the next target above that the estimate still passes is checked, and
    # the rest of the search runs on exact checks (up to the full count, which always passes:
    # its decimation is the input itself).
    lo, hi = _bisect(probe, lo, hi, resolution, exact=False)
    if hi != active and not probe(hi, exact=True):
        while True:
            lo = hi
            hi = next((n for n in sorted(probe.results) if n > lo and probe(n)), active)
            if hi == active or probe(hi, exact=True):
                break
        lo, hi = _bisect(probe, lo, hi, resolution, exact=True)
    if hi not in probe.results:
        probe(hi, exact=True)  # the full count: only reached when every smaller target failed
    result, error, passed = probe.results[hi]
    if not passed:
        raise TopStocError(f"no decimation meets max_error {bound:g}: even all {hi} vertices measure {error:g}")
    failed_error = probe.results[lo][1] if lo in probe.results else math.inf
    return result, ErrorBoundReport(
        max_error=bound, achieved_error=error, target_vertices=hi, output_vertices=result.num_vertices,
        failed_target=lo, failed_error=failed_error, resolution=resolution_count(hi, resolution),
        probes=probe.probes, queries=probe.queries, seconds=time.perf_counter() - started)
