"""Mirror-symmetric decimation (X, Y or Z, like Blender's Decimate modifier): a mesh that is
symmetric about a coordinate plane through the origin gives a symmetric result.

How: every vertex is paired with its mirror partner (the vertex at the mirrored position,
within a tolerance). A plain decimation chooses the samples; the samples on the positive side
of the plane (and on it) are kept and each one's partner is added, so the sample set is mirror
symmetric. The mesh is then rebuilt from that set with ``decimate_with_samples``, which keeps
every topology guarantee and may add repair samples; those are mirrored too and the rebuild
repeats until the set is closed under mirroring (usually once). A sample whose cluster a
neighbour absorbed (a tie in the flood broken differently on the two sides) is not kept: its
partner is dropped too and the mesh rebuilt. Control points (guidance 1) on
either side stay, with their partners. With subsample placement the output vertices are the
samples, so they mirror exactly; filtered placement moves them within clusters that mirror
each other up to ties in the flood, so each moved vertex is averaged with its partner's mirror
image (``mirror_average``) and the output mirrors exactly too.

Vertices without a partner (an asymmetric part of the mesh) keep what the plain decimation
chose for them. A refined result (``refine``) is made symmetric the same way from its kept
vertices, without a second refinement.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
from ..support.errors import TopStocError

AXES = {"X": 0, "Y": 1, "Z": 2}
MAX_ROUNDS = 6


def _keys(points: np.ndarray, cell: float, shift: float) -> np.ndarray:
    """One integer key per point: the grid cell of size ``cell`` (offset by ``shift`` cells)."""
    q = np.floor(points / cell + shift).astype(np.int64)
    q -= q.min(axis=0) if len(q) else 0
    span = q.max(axis=0) + 1 if len(q) else np.ones(3, dtype=np.int64)
    return (q[:, 0] * span[1] + q[:, 1]) * span[2] + q[:, 2]


def mirror_partners(vertices, axis: str = "X", tolerance: float = None) -> np.ndarray:
    """Index of each vertex's mirror partner across the plane ``axis = 0`` (-1: none).

    tolerance: largest distance between a mirrored vertex and its partner (default 1e-5 of the
    bounding-box diagonal). Vertices on the plane are their own partners.
    """
    if axis not in AXES:
        raise TopStocError(f"symmetry axis must be one of {tuple(AXES)}, got {axis!r}")
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    n = len(v)
    partner = np.full(n, -1, dtype=np.int64)
    if n == 0:
        return partner
    diagonal = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))) or 1.0
    tol = tolerance if tolerance is not None else 1e-5 * diagonal
    if not tol > 0:
        raise TopStocError(f"tolerance must be positive, got {tolerance!r}")
    mirrored = v.copy()
    mirrored[:, AXES[axis]] *= -1.0
    both = np.vstack([v, mirrored])
    for shift in (0.0, 0.5):  # a second grid catches pairs split by a cell border in the first
        keys = _keys(both, 2.0 * tol, shift)
        own, wanted = keys[:n], keys[n:]
        order = np.argsort(own, kind="stable")
        sorted_keys = own[order]
        at = np.searchsorted(sorted_keys, wanted)
        hit = (at < n) & (sorted_keys[np.minimum(at, n - 1)] == wanted)
        found = np.flatnonzero(hit & (partner < 0))
        candidates = order[at[found]]
        close = np.linalg.norm(v[candidates] - mirrored[found], axis=1) <= tol
        partner[found[close]] = candidates[close]
    return partner


def symmetric_samples(samples, vertices, partner, axis: str, forced=()) -> np.ndarray:
    """The samples on the positive side of the plane (or without a partner), their partners, and
    every forced vertex with its partner: a set closed under mirroring where partners exist."""
    v = np.asarray(vertices, dtype=np.float64)
    samples = np.asarray(samples, dtype=np.int64)
    side = v[samples, AXES[axis]] >= 0
    lone = partner[samples] < 0
    keep = samples[side | lone]
    forced = np.asarray(forced, dtype=np.int64)
    chosen = np.concatenate([keep, forced])
    mirrored = partner[chosen]
    return np.unique(np.concatenate([chosen, mirrored[mirrored >= 0]])).astype(np.int32)


def _closed(samples, partner) -> np.ndarray:
    mirrored = partner[samples]
    return np.unique(np.concatenate([samples, mirrored[mirrored >= 0]])).astype(np.int32)


def _symmetric_part(vertices, partner) -> np.ndarray:
    """The vertices whose partner is among them too (or who have none)."""
    present = np.zeros(len(partner), dtype=bool)
    present[vertices] = True
    mirrored = partner[vertices]
    keep = (mirrored < 0) | present[np.maximum(mirrored, 0)]
    return np.asarray(vertices, dtype=np.int64)[keep]


class SymmetryWarning(UserWarning):
    """A symmetric decimation of a mesh that is not (wholly) symmetric: the result is symmetric
    only where the input is."""


def symmetry_warning(partner, axis: str):
    """The warning text when vertices have no mirror partner across ``axis = 0``, else None."""
    unpaired = int(np.count_nonzero(partner < 0))
    if unpaired == 0:
        return None
    share = 100.0 * unpaired / len(partner)
    return (f"--symmetry {axis.lower()}: the mesh is not symmetric across the plane {axis.lower()} = 0: "
            f"{unpaired} of {len(partner)} vertices ({share:.3g} %) have no mirror partner; the result is "
            "symmetric only where the input is")


def parse_axis(text) -> str:
    """'x' / 'X' -> 'X'; ValueError naming the accepted axes otherwise."""
    axis = str(text).strip().upper()
    if axis not in AXES:
        raise TopStocError(f"symmetry axis must be one of {', '.join(AXES)}, got {text!r}")
    return axis


def decimate_mirrored(mesh, axis=None, **options):
    """``mesh.decimate(**options)``, made mirror-symmetric across ``axis`` ("X", "Y", "Z") when it
    is given."""
    from .decimate import run_job
    from .job import make_job

    return run_job(mesh, make_job(mesh, symmetry=axis, **options))


def decimate_symmetric(mesh, axis: str = "X", *, tolerance: float = None, **options):
    """``mesh.decimate(...)`` with a mirror-symmetric result (see the module docs).

    The result's ``parameters`` record ``symmetry`` (the axis) and its ``samples`` reproduce it
    through ``decimate_with_samples`` like any result. placement None (the mode's choice) is
    subsample: the mirrored rebuild keeps input vertices in either mode.
    """
    return decimate_mirrored(mesh, parse_axis(axis), symmetry_tolerance=tolerance, **options)


def decimate_job_mirrored(mesh, job):
    """Runs a DecimationJob with a ``symmetry`` axis (core/api/job.py): the plain job's draw, mirrored.
    The result's stats keep the plain job's target (``mirrored_from``: the plain result's
    vertices), so a mirrored set larger than the target is reported over budget (core/api/budget.py)."""
    from .decimate import decimate_with_samples, run_job

    axis, placement = job.symmetry, job.placement
    layout = dict(regions=job.regions, borders=job.borders, feature_angle=job.feature_angle)
    plain = run_job(mesh, job.plain())
    partner = mirror_partners(mesh.vertices, axis, job.symmetry_tolerance)
    message = symmetry_warning(partner, axis)
    if message:  # stacklevel: the caller of decimate_mirrored (through run_job)
        warnings.warn(message, SymmetryWarning, stacklevel=4)
    forced = np.flatnonzero(job.guidance >= 1.0) if job.guidance is not None else ()
    refined = plain.stats.refine_vertices > 0
    chosen = np.asarray(plain.kept if refined else plain.samples, dtype=np.int64)
    samples = symmetric_samples(chosen, mesh.vertices, partner, axis, forced)
    result = plain
    for _ in range(MAX_ROUNDS):
        result = decimate_with_samples(mesh, samples, placement=placement, **layout)
        kept = np.asarray(result.kept, dtype=np.int64)
        added = np.setdiff1d(np.asarray(result.samples, dtype=np.int64), samples)  # topology repairs
        # a sample whose cluster a neighbour absorbed is not kept: drop its partner too
        following = _closed(np.concatenate([_symmetric_part(kept, partner), added]), partner)
        if len(added) == 0 and len(_symmetric_part(kept, partner)) == len(kept):
            break
        samples = following
    parameters = dict(plain.parameters, symmetry=axis, symmetric_samples=len(samples))
    vertices = mirror_average(result.vertices, result.kept, partner, axis) if placement == "filtered" \
        else result.vertices
    stats = dataclasses.replace(result.stats, target_vertices=plain.stats.target_vertices,
                                target_triangles=plain.stats.target_triangles, forced=plain.stats.forced,
                                loop_forced=plain.stats.loop_forced,
                                control_points=plain.stats.control_points, mirrored_from=plain.num_vertices,
                                replayed=False)
    return dataclasses.replace(result, vertices=vertices, parameters=parameters, stats=stats)


def mirror_average(positions, kept, partner, axis: str) -> np.ndarray:
    """Moved output vertices made exactly symmetric: each one and its partner's mirror image are
    averaged (a vertex on the plane is projected onto it). The clusters of two partners mirror
    each other up to ties in the flood, so this moves vertices by a fraction of a cluster."""
    positions = np.asarray(positions, dtype=np.float64)
    kept = np.asarray(kept, dtype=np.int64)
    output_of = np.full(len(partner), -1, dtype=np.int64)
    output_of[kept] = np.arange(len(kept))
    mirrored_input = partner[kept]
    other = np.where(mirrored_input >= 0, output_of[np.maximum(mirrored_input, 0)], -1)
    paired = np.flatnonzero(other >= 0)
    flip = np.ones(3)
    flip[AXES[axis]] = -1.0
    out = positions.copy()
    out[paired] = 0.5 * (positions[paired] + positions[other[paired]] * flip)
    return out
