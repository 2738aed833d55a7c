"""Error-bounded decimation (docs/design.md §2.11): the fewest vertices whose symmetric Hausdorff error stays
under a bound.

A re-decimation of a prepared mesh costs milliseconds, so the search simply tries vertex
targets: it brackets the answer by factors of four, then bisects (geometrically) until the
smallest passing target and the largest failing one are within the resolution. Every probe
uses the same seed and the same sampling of the original, so the search is reproducible and
every error is measured the same way. Error need not fall monotonically with the vertex count
(each count draws other samples); the guarantee is the one the search can check: the returned
decimation's error is within the bound (measured as a guaranteed upper bound of the exact
maximum, by bounded-error refinement), and the target ``resolution`` below it
(``failed_target``) was measured above the bound.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

from .hausdorff import as_surface
from ..support import params
from ..support.native import engine
from ..support.errors import TopStocError

DEFAULT_SEARCH_SAMPLES = 50_000
MAX_TOLERANCE = 1e-3  #: relative bracket of the Hausdorff max in each probe (see hausdorff.py)


@dataclass(frozen=True)
class ErrorBoundReport:
    """How the error-bounded search went. Errors are absolute (same units as the mesh)."""

    max_error: float            #: the bound, absolute
    achieved_error: float       #: guaranteed upper bound of the returned decimation's symmetric Hausdorff max
    target_vertices: int        #: vertex target of the returned decimation
    output_vertices: int        #: vertices it has (repairs may add a few)
    failed_target: int          #: largest probed target above the bound (0: none below)
    failed_error: float         #: its error (inf when failed_target is 0)
    resolution: int             #: failed_target and target_vertices are at most this far apart
    probes: list = field(default_factory=list)  #: (target, output vertices, error) per probe, in order
    step: float = 0.0           #: sample spacing of the measurement
    samples: int = 0            #: samples on the original
    seconds: float = 0.0


def resolution_count(target: int, resolution: float) -> int:
    """Vertex-count resolution at ``target`` for a relative resolution."""
    return max(1, int(math.floor(resolution * target)))


def search_vertex_count(mesh, max_error: float, decimate_at: Callable[[int], object], *,
                        relative: bool = False, resolution: float = 0.01,
                        samples: int = DEFAULT_SEARCH_SAMPLES):
    """Finds the smallest vertex target whose decimation has symmetric error <= max_error.

    mesh: the prepared topstoc.Mesh; decimate_at(n): its decimation with n target vertices
    (fixed seed and options). relative: max_error is a fraction of the bounding-box diagonal
    (0.01 = 1 %). resolution: stop when the failing and passing targets differ by at most
    ``max(1, resolution * target)``. samples: measurement density on the original.
    Returns (DecimateResult, ErrorBoundReport).
    """
    max_error = params.number("max_error", max_error, 0)
    resolution = params.number("resolution", resolution, 0, 1, high_open=True)
    samples = params.integer("samples", samples, 1, 2**62)
    started = time.perf_counter()
    original = as_surface(mesh, "mesh")
    bound = max_error * original.diagonal if relative else float(max_error)
    original_samples = engine.sample_surface(original, engine.step_for_sample_count(original, samples))
    report = mesh.report()
    active = report.input_vertices - report.isolated_vertices

    probes = []
    results = {}

    def probe(n: int) -> bool:
        result = decimate_at(n)
        measured = engine.hausdorff_with_samples(original, original_samples,
                                                 as_surface(result, "decimation"), percentile=0.0,
                                                 max_tolerance=MAX_TOLERANCE)
        # The guaranteed upper bound, not a sampled lower one: the true maximum can only be
        # smaller, so a probe that passes holds the bound for certain.
        error = measured["symmetric"]["max_upper"]
        probes.append((n, result.num_vertices, error))
        results[n] = (result, error)
        return error <= bound

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
    # Bisect until the bracket is within the resolution.
    while hi - lo > resolution_count(hi, resolution):
        mid = int(round(math.sqrt(lo * hi))) if lo > 0 else hi // 2
        mid = min(max(mid, lo + 1), hi - 1)
        if probe(mid):
            hi = mid
        else:
            lo = mid
    if hi not in results:
        probe(hi)  # the full count: only reached when every smaller target failed
    result, error = results[hi]
    if error > bound:
        raise TopStocError(f"no decimation meets max_error {bound:g}: even all {hi} vertices measure {error:g}")
    failed_error = results[lo][1] if lo in results else math.inf
    return result, ErrorBoundReport(
        max_error=bound, achieved_error=error, target_vertices=hi, output_vertices=result.num_vertices,
        failed_target=lo, failed_error=failed_error, resolution=resolution_count(hi, resolution),
        probes=probes, step=original_samples.step, samples=original_samples.size,
        seconds=time.perf_counter() - started)
