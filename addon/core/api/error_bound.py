"""Error-bounded decimation (docs/design.md §2.11): the fewest vertices whose symmetric Hausdorff error stays
under a bound.

The search tries vertex targets. It brackets the answer by extrapolating the power law error ~
c * count^-a through its last two probes (a = 1 at first, as for a surface), then bisects
(geometrically) until the smallest passing target and the largest failing one are within the
resolution. Every
probe uses the same seed and the original's one measurement surface (its closest-point index
built once), so the search is reproducible. A probe is judged on a cheap estimate first: the
largest distance over about 40,000 points spread on both surfaces (attained, so a probe above the
bound fails for certain; in the bisection, where only the verdict counts, it decides the bound:
see SampledError). A passing target is checked exactly
(topstoc.core.error_estimate.decide_error: the guaranteed bracket of the exact maximum, refined
only as far as deciding the bound needs): at once with ``check_passes`` (quality mode, where a
decimation costs more than a check), else only the answer. A failed check's far point joins the
estimate's points (on the original: that point; on the result: each later result's closest point
to it) and the search climbs above it in steps doubling from two resolutions. Error need not fall monotonically with the vertex count (each count draws other
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
#: the bracketing's estimates (whose values steer it) are exact above this share of the bound:
#: points nearer than that stop at the first triangle that near (SampledError's exact_above)
EXACT_ABOVE = 0.25

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
    #: (target, output vertices, error) per probe, in order (a probe the bisection's estimate passed:
    #: a value between its sampled max and the bound)
    probes: list = field(default_factory=list)
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

    def __call__(self, n: int, exact: bool = False, verdict: bool = False) -> bool:
        """Decimates at n (once), records (result, error); True when within the bound. verdict:
        only the verdict counts (bisection): a passing estimate records a value within the bound,
        at least the sampled max, rather than that max (SampledError's ``within``)."""
        result = self.results[n][0] if n in self.results else self.decimate_at(n)
        if exact:
            decided = decide_error(self.mesh, result, self.bound, original_surface=self.original)
            self.queries += decided.queries
            self.exact.add(n)
            passed = decided.upper <= self.bound
            error = decided.upper if passed else decided.estimate
            if decided.witness is not None:
                self.sampled.add_witness(decided.witness)
            if decided.result_witness is not None:
                self.sampled.add_result_witness(decided.result_witness)
        else:
            error = self.sampled(result, self.bound) if verdict else self.sampled(result, exact_above=EXACT_ABOVE * self.bound)
            passed = error <= self.bound
        self.probes.append((n, result.num_vertices, error))
        self.results[n] = (result, error, passed)
        if self.progress is not None and self.progress(len(self.probes), n, result.num_vertices, error, passed) is False:
            raise Cancelled("the error-bounded search was cancelled")
        return passed

    def judge(self, n: int) -> bool:
        """The estimate first (above the bound fails for certain), then the exact check."""
        return self(n, verdict=True) and self.exactly(n)

    def exactly(self, n: int) -> bool:
        """The exact check of n, made once (a later call reads its verdict)."""
        return self.results[n][2] if n in self.exact else self(n, exact=True)


def _bracket(probe: _Probes, active: int, resolution: float) -> tuple:
    """A failing and a passing target on the estimate (lo 0: none below fails; hi ``active``: the
    full count, never probed). Each step extrapolates the power law through the last two probes (a
    first guess of error ~ 1/count, as for a surface) and aims a quarter past the bound."""
    lo, hi, n, previous = 0, active, min(active, max(4, active // 64)), None
    while (lo == 0 or hi == active) and hi - lo > resolution_count(hi, resolution) and hi > 4:
        passed = probe(n)
        lo, hi = (lo, n) if passed else (n, hi)
        error, slope = probe.results[n][1], 1.0
        if previous is not None and error > 0 and probe.results[previous][1] > 0 and error != probe.results[previous][1]:
            slope = math.log(probe.results[previous][1] / error) / math.log(n / previous)
            slope = min(max(slope, 0.25), 4.0)
        step = (error / probe.bound) ** (1 / slope) if error > 0 and probe.bound > 0 else 0.25
        step = min(max(step * (0.8 if passed else 1.25), 1 / 16), 16)
        previous, n = n, min(max(int(round(n * step)), lo + 1, 1), hi - 1)
    return lo, hi


def _climb(probe: _Probes, judge: Callable[[int], bool], failed: int, active: int, resolution: float) -> tuple:
    """(lo, hi) above ``failed``, a target the estimate passed and the exact check failed: steps up
    from it, each twice the last (from two resolutions), judging each, up to the smallest probed
    target above that the estimate still passes (hi then still to check exactly) or the full count.
    The answer usually lies a few hundredths above, where a bisection toward the full count
    probed many targets."""
    lo, step = failed, 2 * resolution_count(failed, resolution)
    cap = next((n for n in sorted(probe.results) if n > failed and probe(n, verdict=True)), active)
    while lo + step < cap:
        if judge(lo + step):
            return lo, lo + step
        lo, step = lo + step, 2 * step
    return lo, cap


def _bisect(judge: Callable[[int], bool], lo: int, hi: int, resolution: float) -> tuple:
    """Narrows (lo fails, hi passes by ``judge``) geometrically until within the resolution. (The
    error's plateaus and noise near the bound defeat interpolation: it probed more than this.)"""
    while hi - lo > resolution_count(hi, resolution):
        mid = int(round(math.sqrt(lo * hi))) if lo > 0 else hi // 2
        mid = min(max(mid, lo + 1), hi - 1)
        if judge(mid):
            hi = mid
        else:
            lo = mid
    return lo, hi


def search_vertex_count(mesh, max_error: float, decimate_at: Callable[[int], object], *,
                        relative: bool = False, resolution: float = 0.01, check_passes: bool = False,
                        progress=None):
    """Finds the smallest vertex target whose decimation has symmetric error <= max_error.

    mesh: the prepared topstoc.Mesh; decimate_at(n): its decimation with n target vertices
    (fixed seed and options). relative: max_error is a fraction of the bounding-box diagonal
    (0.01 = 1 %). resolution: stop when the failing and passing targets differ by at most
    ``max(1, resolution * target)``. check_passes: check every target the estimate passes exactly
    at once (fewer decimations, more exact checks: for when a decimation costs more than a check)
    rather than only the answer. progress: ``progress(probe, target, vertices, error,
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

    lo, hi = _bracket(probe, active, resolution)
    if not check_passes:
        lo, hi = _bisect(lambda n: probe(n, verdict=True), lo, hi, resolution)  # on the estimate alone
    # The estimate passes hi: check it exactly. Should the check fail, its far point joins the
    # estimate's points and the next probed target above that the estimate still passes is
    # checked (up to the full count, which always passes: its decimation is the input itself).
    judge = probe.judge if check_passes else lambda n: probe(n, exact=True)
    while hi != active and not probe.exactly(hi):
        lo, hi = _climb(probe, judge, hi, active, resolution)
    # then on to the resolution on exact checks (the estimate first with check_passes)
    lo, hi = _bisect(judge, lo, hi, resolution)
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
