"""TopStoc decimation on numpy arrays (thesis 4.1, 4.3-4.6; docs/design.md §2).

The output's vertices are input vertices (or, with ``placement="filtered"``, points close to
them); each output triangle comes from one input triangle and keeps its orientation. The
topology of every manifold component (components, genus, boundary loops) is kept; where plain
clustering would break it, samples are added and the result says how many.

Three modes (``mode=``): ``"quality"`` (the default) runs TopStoc to a few times the target,
then quadric-ordered edge collapses thin it to the target (``refine``, filtered placement);
``"best"`` is quality with a last least-squares fit of the result to the input on large results
too (smaller ones always get it): a lower mean error for more time; ``"fast"`` is the thesis'
plain TopStoc (what the live preview shows while the slider moves), except on a sliver-heavy
mesh of up to 250,000 vertices (a UV sphere of many segments, a CAD strip), where TopStoc's
clusters, grown by hops, cut across the surface: that mesh is collapsed whole, keeping input
positions.

Guidance convention (docs/design.md §2.2): ``u`` in [-1, 1] per vertex. ``u = 0`` follows the global
target; ``u > 0`` asks for more density, ``u < 0`` for less: a density multiplier
``((1 + u) / (1 - u))**2`` (u = 0.5: nine times, -0.5: a ninth). ``u = 1`` is a control point
(always kept), ``u = -1`` is never sampled unless the topology needs it. Paint redistributes
the budget, it does not change it: the target is met within 1 % whatever is painted, in both
modes, and a painted region gets the same share of it in both. Only control points (and
corners of borders) or the topology can push the count over; ``stats.over_budget`` and
``stats.over_budget_reason`` then say by how much and why.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional, Sequence

import numpy as np

from . import budget
from .invariants import invariants_kept
from ..support import params
from ..support.counts import MeshCounts
from ..support.errors import TopStocError
from .job import (  # noqa: F401 - View, Box and the constants are this module's public names too
    ATTRIBUTE_WEIGHT, DENSITY_MODES, MAX_ATTRIBUTE_CHANNELS, MODES, PLACEMENTS, QUALITY_COLLAPSES, QUALITY_REFINE,
    Box, DecimationJob, View, attribute_arrays, guidance_values, make_job, target_vertex_count)
from ..support.native import engine

#: a flag another thread sets to stop a decimation (run_job's ``cancel``)
CancelFlag = engine.CancelFlag

if TYPE_CHECKING:  # for annotations only: mesh.py imports this module
    from .mesh import Mesh


@dataclass(frozen=True)
class DecimateStats:
    """How a decimation went."""

    target_vertices: int        #: what was asked for (vertex count)
    selected: int               #: samples drawn before repairs
    forced: int                 #: corners and control points among them
    loop_forced: int            #: of those, three vertices of each short boundary loop (the holes') and the winding seams' corners
    density_rejected: int       #: candidates skipped by density control
    guided: bool                #: guidance, view or boxes changed the probabilities
    expected_vertices: float    #: sum of the sampling probabilities
    rate: float                 #: base rate k used for the probabilities
    fast_path: bool             #: candidate faces collected during the flood
    #: the draw for the target updated the kept flood of an earlier decimation of this mesh (a
    #: nearby target, same seed) instead of flooding afresh; the result is the same (see
    #: Mesh.layout_and_floods; the lower draws made when repairs overshoot flood afresh)
    flood_updated: bool
    repair_rounds: int          #: re-flood rounds needed to keep the topology
    repairs: int                #: samples added to keep the topology
    top_up: int                 #: samples added to make up for clusters absorbed by neighbours
    issues_found: dict          #: what the checks found over all rounds
    issues_remaining: dict      #: what was left (all zero unless the round limit was hit)
    seconds: dict               #: per stage: sampling, clustering, checking, output, refine, verify (the final output check)
    refine_vertices: int = 0    #: target of the quadric refinement (0: not refined)
    refine_triangles: int = 0   #: its triangle target, when it had one
    refine_collapses: int = 0   #: collapses the refinement made
    #: the refinement's collapses kept input positions (fast mode's, where its pass ended above the target)
    refine_keeps_positions: bool = False
    #: the refinement stopped above its target where only triangles thinner than the input's own
    #: needles would have gone on (a mesh made mostly of slivers)
    shape_floor: bool = False
    #: the refinement stopped at twice its target or more where only collapses that flip, fold or
    #: thin triangles would have gone on (a thin, curved part: budget.py's "folds")
    fold_floor: bool = False
    #: quality mode's tail stopped above its target where only collapses laying triangles far from
    #: the input (over an opening) would have gone on (budget.py's "error guard")
    far_guard: bool = False
    #: a draft whose full decimation collapses it further (above its target, or zero-area triangles
    #: left for the clean-up): the frame is the plain pass
    collapses_skipped: bool = False
    output_vertices: int = 0    #: vertices of the result
    #: the final check of the output against the input's components (manifold, orientation,
    #: components, Euler characteristic, boundary loops, duplicates, finite coordinates; see
    #: native verify.hpp). All zero except ``zero_area`` whenever ``topology_kept`` is True: a
    #: violation the repairs did not report raises instead of returning.
    output_check: dict = field(default_factory=dict)
    #: the final check ran; False only for a draft (``decimate(draft=True)``), which leaves it out
    output_checked: bool = True
    control_points: int = 0     #: vertices the guidance keeps (u = 1)
    zero_area_input: int = 0    #: input triangles without area (in double precision)
    #: a mirror-symmetric result (core/api/symmetry.py): vertices of the plain decimation it was made from (else 0)
    mirrored_from: int = 0
    output_triangles: int = 0   #: triangles of the result
    #: re-created from a sample list (decimate_with_samples): no target was asked, none missed
    replayed: bool = False
    target_triangles: int = 0   #: the triangle target asked for (0: none)
    #: vertices of the result on non-manifold edges (three or more triangles; counted when the input has some)
    nonmanifold_vertices: int = 0
    #: triangles of the result that are pieces of their own (an unwelded mesh is made of them);
    #: each piece keeps its triangle. Counted when the input has more pieces than a tenth of its faces
    loose_triangles: int = 0
    #: triangles of the input that are pieces of their own, counted with loose_triangles (an
    #: unwelded mesh: weld it; pieces of several triangles, such as leaf cards, leave this lower)
    loose_input: int = 0
    #: holes (boundary loops) of the input, each kept with at least three vertices; counted when
    #: the result lands over its target and the input has boundary edges enough to hold it there
    holes: int = 0
    #: components of the input with a boundary, counted with holes: where the holes are about one a
    #: component, they are the outlines of separate open pieces (hair strips, cards), not holes
    open_pieces: int = 0
    #: components of the input, counted when the result lands over its target
    pieces: int = 0
    #: vertices of the result on the borders the caller gave (a change of region: material, UV
    #: island; a flagged edge: seam, sharp), each kept on its course; counted when the result lands
    #: over its target and borders were given
    border_vertices: int = 0
    #: when the partition checks left issues (they cannot judge some non-manifold inputs' own
    #: clusters): every input component's invariants match its output's (core/api/invariants.py);
    #: None when it was not needed
    invariants_kept: Optional[bool] = None

    @property
    def over_budget(self) -> int:
        """Vertices above the target when the result misses it by more than 1 % (else 0)."""
        excess = self.output_vertices - self.target_vertices
        return excess if excess > budget.tolerance(self.target_vertices) else 0

    @property
    def over_budget_reason(self) -> str:
        """Why the result is over budget: "" (it is not), "control points" (the vertices painted to
        stay outnumber the target), "non-manifold edges" (half the result's vertices lie on them),
        "borders" (so do the corners of borders), "symmetry" (the
        mirrored sample set) or "topology" (samples the topology needed); see core/api/budget.py."""
        return budget.over_reason(self) if self.over_budget else ""

    @property
    def target_missed(self) -> Optional[budget.MissedTarget]:
        """How far the result is from its vertex target and why, or None when it met it."""
        return budget.missed_target(self)

    @property
    def topology_kept(self) -> Optional[bool]:
        """True when the final check passed and either no topological issue remained (see
        issues_remaining) or every component kept its invariants (see invariants_kept); None for
        a draft, whose output was not re-checked."""
        if not self.output_checked:
            return None
        return not self.check_violations and (not self.issues_left or bool(self.invariants_kept))

    @property
    def topology_warning(self) -> str:
        """"topology NOT kept: 5 lost components, ..." for a report, or "" when it was kept (or not
        checked: a draft)."""
        if self.topology_kept is not False:
            return ""
        counts = {**{k: v for k, v in self.issues_remaining.items() if k != "sliver"},
                  **{k: v for k, v in self.output_check.items() if k != "zero_area"}}
        found = ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in counts.items() if v)
        return "topology NOT kept: " + found + ("" if self.check_violations else
                                                 " (and an input component's invariants changed)")

    @property
    def issues_left(self) -> int:
        """Topological issues the partition checks left (issues_remaining but slivers)."""
        return sum(v for k, v in self.issues_remaining.items() if k != "sliver")

    @property
    def check_violations(self) -> int:
        """Violations the final output check found (output_check but zero-area triangles)."""
        return sum(v for k, v in self.output_check.items() if k != "zero_area")


@dataclass(frozen=True)
class DecimateResult(MeshCounts):
    """A decimated mesh and how it maps to the input.

    ``kept[i]`` is the input vertex that output vertex ``i`` stands for; ``face_source[j]`` the
    input triangle output triangle ``j`` came from; ``corner_source[j, c]`` the input corner
    (``3 * triangle + slot``) whose attributes (UVs, colours, split normals) output corner
    ``(j, c)`` should take: a corner of the kept vertex on the same side of every border.
    ``labels[v]`` is the output vertex whose cluster holds input vertex ``v`` (-1 for vertices
    in no triangle). ``samples`` (with the same mesh, borders and placement; for a refined
    result also ``stats.refine_vertices``, ``stats.refine_triangles``, the guidance and the
    attributes) reproduces the result exactly
    through ``Mesh.decimate_with_samples``.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    kept: np.ndarray
    face_source: np.ndarray
    corner_source: np.ndarray
    labels: np.ndarray
    samples: np.ndarray
    stats: DecimateStats
    parameters: dict = field(default_factory=dict)
    #: with ``max_error``: how the error-bounded search went (see topstoc.core.api.error_bound)
    error_bound: Optional[object] = None

    def aspect_ratio(self) -> dict:
        """Triangle aspect ratio (thesis eq. 4.2): mean, max and count of degenerate ones."""
        return engine.aspect_ratio_stats(self.vertices, self.triangles)


def _renamed(old: str, old_value, new: str, new_value):
    """The value given for a renamed keyword: the old name still works, with a warning."""
    if old_value is None:
        return new_value
    if new_value is not None:
        raise TopStocError(f"give {new} only, not also its old name {old}")
    warnings.warn(f"decimate({old}=...) is deprecated; use {new}=...", DeprecationWarning, stacklevel=3)
    return old_value


def decimate(mesh: Mesh, ratio: Optional[float] = None, target_vertices: Optional[int] = None,
             target_triangles: Optional[int] = None, *, vertices: Optional[int] = None,
             triangles: Optional[int] = None, seed: int = 0, adaptivity: float = 0.5,
             flat_floor: float = 0.25, area_weighted: bool = False, feature_angle: float = 0.0,
             density: str = "off", density_rings: int = 0,
             density_ratio: float = 2.0, density_epsilon: float = 0.0, guidance=None,
             regions=None, borders=None, view: Optional[View] = None,
             boxes: Sequence[Box] = (), mode: str = "quality", placement: Optional[str] = None,
             fast_path: Optional[bool] = None, max_repair_rounds: int = 200, refine: Optional[float] = None,
             max_error: Optional[float] = None, relative: bool = False, attributes=None,
             attribute_weights=None, draft: bool = False) -> DecimateResult:
    """Decimates ``mesh`` with TopStoc. Give exactly one target.

    ratio: fraction of the vertices to keep, in (0, 1]. target_vertices / target_triangles:
    counts (``vertices=`` / ``triangles=`` are their deprecated old names).
    seed: the same seed gives the same mesh. adaptivity: 0 samples uniformly, 1 follows the
    normal-deviation weights fully. flat_floor: flat regions keep at least this fraction of the
    base rate (the thesis' tweak against slivers). area_weighted: probabilities per unit area
    instead of per vertex (for irregularly tessellated meshes, e.g. CAD exports).
    feature_angle: creases sharper than this many radians are kept as borders (sampled as curves,
    never crossed; good for hard-surface models, costly on noisy scans; 0 = off).
    density: Poisson-disk rejection of samples,
    "off", "uniform" (rings), "adaptive" (thesis 4.1.2: density_ratio = eps_big / eps_small)
    or "euclidean" (density_epsilon, 0 = automatic). guidance: u per vertex (module docs).
    regions: an id per input triangle (materials, UV islands), borders: (k, 2) vertex pairs;
    no cluster crosses either, and both survive exactly. view, boxes: see View and Box.
    mode: "quality" (default): placement "filtered" and quadric collapses after a TopStoc pass
    (see QUALITY_COLLAPSES); "fast": the thesis' TopStoc, placement "subsample", no refinement
    (except where its pass ends above the target: repairs stalled on non-manifold or
    inconsistently oriented input, or a topology that needs more vertices than drawn; then the
    collapses finish it, keeping input positions; docs/design.md §2.7; and on a sliver-heavy
    mesh of up to 250,000 vertices, collapsed whole keeping input positions); "best": quality, then
    a result above 1,400 triangles whose collapses started from the whole mesh (up to
    250,000 vertices) is fitted to the input as smaller ones always are, each
    move kept only where the max error does not grow (about 10 % lower mean error on scans for
    1.4-1.6 times quality's time; docs/bench_notes/large-fit.md).
    placement and refine, when given, override what the mode sets.
    placement: "subsample" keeps the first pass's input positions, "filtered" moves surface
    vertices to the quadric-optimal point of their cluster (borders stay). In quality mode the
    collapses themselves place a vertex joining two free vertices at the quadric optimum either
    way; placement only decides the final re-fit.
    refine: None = the mode's own (quality: the whole mesh up to 250,000 vertices, else a first
    pass of the target plus max(QUALITY_COLLAPSES, target / 4) vertices and at least
    min(8 * target, 250,000), up to 500,000 vertices at least 125,000; fast: 0). 0 = off
    (fastest). f >= 1: TopStoc
    keeps f times the target (so refine=1 leaves the collapses almost nothing to do), then edge
    collapses ordered by quadric error against the input thin it to the target (topology and
    borders kept, painted regions keeping their share of the budget). Lower error at a higher
    cost.
    attributes: UVs, colours, normals... that should survive the collapses: (n, k) per vertex
    or (m, 3, k) per corner of the caller's triangles (per corner for UVs with seams). They
    enter the collapse cost as generalised quadrics (docs/design.md §2.10): with weight w, a
    difference d in a channel costs as much as moving the surface by w * d bounding-box
    diagonals. attribute_weights: a number or one per channel (default ATTRIBUTE_WEIGHT).
    Only the refinement (quality mode) uses them; output attributes still come from the input
    through corner_source (topstoc.core.carry.attributes interpolates those of moved vertices).
    max_error: the fewest vertices whose symmetric Hausdorff error stays within this bound
    (absolute, or a fraction of the bounding-box diagonal with ``relative=True``), found by a
    search over re-decimations with the same seed; ``result.error_bound`` tells how it went.
    draft: a live-preview frame (fast mode only): the same vertices and triangles (or, with
    ``stats.collapses_skipped``, the plain pass the full decimation collapses further), without
    face_source, corner_source and labels (empty arrays) and without the final output check
    (``stats.output_checked`` False, ``stats.topology_kept`` None). The partition checks and
    repairs still run; what a draft skips is the independent re-check, so show drafts while a
    slider moves and decimate in full for what is kept.
    """
    job = make_job(mesh, ratio, _renamed("vertices", vertices, "target_vertices", target_vertices),
                   _renamed("triangles", triangles, "target_triangles", target_triangles), max_error=max_error,
                   relative=relative, seed=seed, adaptivity=adaptivity, flat_floor=flat_floor,
                   area_weighted=area_weighted, feature_angle=feature_angle, density=density,
                   density_rings=density_rings, density_ratio=density_ratio, density_epsilon=density_epsilon,
                   guidance=guidance, regions=regions, borders=borders, view=view, boxes=boxes, mode=mode,
                   placement=placement, fast_path=fast_path, max_repair_rounds=max_repair_rounds, refine=refine,
                   attributes=attributes, attribute_weights=attribute_weights, draft=draft)
    return run_job(mesh, job)


def run_job(mesh: Mesh, job: DecimationJob, progress=None, cancel: Optional[CancelFlag] = None) -> DecimateResult:
    """Runs a DecimationJob (core/api/job.py): mirrored (core/api/symmetry.py), error-bounded (a search
    over vertex counts, core/api/error_bound.py) or one engine call. progress: the error-bounded
    search's ``progress(probe, target, vertices, error, passed)`` (False cancels; error_bound.py).
    cancel: a CancelFlag another thread may set to stop the engine at its next check (raises
    Cancelled; a mirrored job runs to its end)."""
    if job.symmetry is not None:
        from .symmetry import decimate_job_mirrored

        return decimate_job_mirrored(mesh, job)
    if job.target.max_error is not None:
        from .error_bound import search_vertex_count

        result, report = search_vertex_count(mesh, job.target.max_error, lambda count: run_job(mesh, job.at(count), cancel=cancel),
                                             relative=job.target.relative, progress=progress,
                                             check_passes=job.mode != "fast")
        return dataclasses.replace(result, error_bound=report, parameters={
            **result.parameters, "max_error": job.target.max_error, "relative": job.target.relative})
    layout, floods, snapshots = mesh.kept_for_reuse(job.regions, job.borders, job.feature_angle)
    raw = engine.decimate(mesh.native, layout, job, flood_caches=floods, cancel=cancel, collapse_snapshots=snapshots)
    return _result(raw, job.parameters(), mesh, job)


def warm_up(mesh: Mesh, job: DecimationJob, cancel: Optional[CancelFlag] = None) -> bool:
    """Builds what a later ``run_job`` of ``job``, or of it at a lower vertex count, resumes from
    (the first collapse run's state and the input's search structure, kept by the mesh: see
    Mesh.kept_for_reuse), so that it spends only the part that depends on its target; the
    results stay the same to the bit. True when a state is kept for such a run (a quality job of
    a mesh collapsed whole, without guidance); cancel as in run_job (raises Cancelled)."""
    if job.symmetry is not None or job.target.max_error is not None or job.target.triangles is not None:
        return False
    layout, _floods, snapshots = mesh.kept_for_reuse(job.regions, job.borders, job.feature_angle)
    if snapshots is None:
        return False
    return engine.warm_up(mesh.native, layout, job, snapshots, cancel=cancel)


#: DecimateStats fields counted in Python; every other field is the engine result's of the same name
_COUNTED_HERE = {"output_vertices", "output_triangles", "target_triangles", "control_points", "zero_area_input",
                 "mirrored_from", "replayed", "nonmanifold_vertices", "loose_triangles", "loose_input", "holes",
                 "open_pieces", "pieces", "border_vertices", "invariants_kept"}


def vertices_on_nonmanifold_edges(triangles: np.ndarray) -> int:
    """Vertices on an edge of three or more of these triangles."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    return len(np.unique(unique[counts > 2]))


def loose_triangles(triangles: np.ndarray) -> int:
    """Triangles whose three corners are in no other triangle (each a piece of its own)."""
    t = np.asarray(triangles).reshape(-1, 3)
    if len(t) == 0:
        return 0
    faces = np.bincount(t.ravel())
    return int(np.count_nonzero((faces[t] == 1).all(axis=1)))


def vertices_on_borders(num_vertices: int, triangles, kept, regions=None, borders=None) -> int:
    """Vertices of a result (input vertex ``kept`` of each) on a border: in triangles of two
    regions or more, or at an end of a given border edge."""
    on = np.zeros(num_vertices, dtype=bool)
    if regions is not None:
        t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        r = np.asarray(regions).reshape(-1)
        some = np.zeros(num_vertices, dtype=r.dtype)
        some[t.reshape(-1)] = np.repeat(r, 3)  # one region of each vertex's triangles
        for j in range(3):  # a vertex with a triangle of another region is on a border
            on[t[r != some[t[:, j]], j]] = True
    if borders is not None and np.size(borders):
        on[np.asarray(borders, dtype=np.int64).reshape(-1)] = True
    return int(np.count_nonzero(on[np.asarray(kept, dtype=np.int64)]))


def _over_target_counts(stats: DecimateStats, report: dict, mesh: Mesh, kept, job) -> DecimateStats:
    """The counts that tell what holds a result over its target (budget.py's details): the
    input's pieces; its holes and open pieces where they may hold it (three vertices a hole, a
    quarter of the result's vertices, and loose triangles do not explain it already: the input's
    topology is not computed for every miss); the result's vertices on the borders given."""
    counts = {"pieces": report["components"]}
    if 4 * report["boundary_edges"] >= stats.output_vertices and 12 * stats.loose_triangles < stats.output_vertices:
        components = mesh.input_topology.components
        counts["holes"] = sum(len(c.boundary_loops) for c in components)
        counts["open_pieces"] = sum(1 for c in components if c.boundary_loops)
    if job is not None and (job.regions is not None or job.borders is not None):
        counts["border_vertices"] = vertices_on_borders(len(mesh.vertices), mesh.triangles, kept, job.regions,
                                                        job.borders)
    return dataclasses.replace(stats, **counts)


def _result(raw: dict, parameters: dict, mesh: Mesh, job: Optional[DecimationJob] = None) -> DecimateResult:
    report = mesh.native.report  # a dict made on each read: read once
    stats = DecimateStats(**{f.name: raw[f.name] for f in dataclasses.fields(DecimateStats)  # same names
                             if f.name not in _COUNTED_HERE}, output_vertices=len(raw["vertices"]),
                          output_triangles=len(raw["triangles"]),
                          target_triangles=0 if job is None else int(job.target.triangles or 0),
                          control_points=0 if job is None else job.control_points,
                          zero_area_input=report["zero_area_triangles"], replayed=job is None,
                          nonmanifold_vertices=vertices_on_nonmanifold_edges(raw["triangles"])
                          if report["nonmanifold_edges"] else 0,
                          loose_triangles=loose_triangles(raw["triangles"])
                          if 10 * report["components"] >= report["input_triangles"] else 0,
                          loose_input=mesh.loose_triangles
                          if 10 * report["components"] >= report["input_triangles"] else 0)
    missed = stats.target_missed
    if missed is not None and missed.off > 0:
        stats = _over_target_counts(stats, report, mesh, raw["kept"], job)
    if stats.output_checked and stats.issues_left and not stats.check_violations:
        kept = invariants_kept(mesh.input_topology, raw["vertices"], raw["triangles"], raw["kept"])
        stats = dataclasses.replace(stats, invariants_kept=kept)
    return DecimateResult(vertices=raw["vertices"], triangles=raw["triangles"], kept=raw["kept"],
                          face_source=raw["face_source"], corner_source=raw["corner_source"],
                          labels=raw["labels"], samples=raw["samples"], stats=stats,
                          parameters=parameters)


@dataclass(frozen=True)
class SampleReplay:
    """A decimation to re-create from its sample list, as the engine's decimate_with_samples reads
    it (made by decimate_with_samples once every value is checked)."""

    samples: np.ndarray
    placement: str = "subsample"
    max_repair_rounds: int = 200
    refine_vertices: int = 0
    refine_triangles: int = 0
    refine_keeps_positions: bool = False
    large_fit: bool = False
    guidance: Optional[np.ndarray] = None           #: u per vertex (guidance_values), or None
    attributes: Optional[np.ndarray] = None         #: corner values (attribute_arrays), or None
    attribute_weights: Optional[np.ndarray] = None  #: one weight per attribute channel, or None


def decimate_with_samples(mesh: Mesh, samples, *, regions=None, borders=None, feature_angle: float = 0.0,
                          placement: str = "subsample", refine_vertices: int = 0, refine_triangles: int = 0,
                          refine_keeps_positions: bool = False, large_fit: bool = False, guidance=None,
                          attributes=None, attribute_weights=None) -> DecimateResult:
    """Re-creates a decimation from ``DecimateResult.samples`` (thesis 4.1.3).

    With the same mesh, regions, borders, feature angle and placement the output is identical.
    A refined result (``refine`` > 0) also needs ``refine_vertices=result.stats.refine_vertices``,
    ``refine_triangles=result.stats.refine_triangles``,
    ``refine_keeps_positions=result.stats.refine_keeps_positions`` and the same ``guidance`` and
    ``attributes``; one of mode "best" also ``large_fit=True``.
    """
    if placement not in PLACEMENTS:
        raise TopStocError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
    samples = np.asarray(samples)
    if samples.ndim != 1 or samples.dtype.kind not in "iu":
        raise TopStocError(f"samples must be a 1-D integer array, got {samples.dtype} {samples.shape}")
    refine_vertices = params.integer("refine_vertices", refine_vertices, 0, 2**31 - 1)
    refine_triangles = params.integer("refine_triangles", refine_triangles, 0, 2**31 - 1)
    feature_angle = params.number("feature_angle (radians)", feature_angle, 0, math.pi)
    attribute_values, attribute_weights = attribute_arrays(mesh, attributes, attribute_weights)
    layout = mesh.feature_layout(regions, borders, feature_angle)
    replay = SampleReplay(samples, placement, refine_vertices=int(refine_vertices),
                          refine_triangles=int(refine_triangles), refine_keeps_positions=bool(refine_keeps_positions),
                          large_fit=bool(large_fit), guidance=guidance_values(mesh, guidance),
                          attributes=attribute_values, attribute_weights=attribute_weights)
    raw = engine.decimate_with_samples(mesh.native, layout, replay)
    return _result(raw, dict(samples=len(samples), placement=placement, feature_angle=feature_angle,
                             refine_vertices=int(refine_vertices), refine_triangles=int(refine_triangles),
                             refine_keeps_positions=bool(refine_keeps_positions), large_fit=bool(large_fit)), mesh)


def sampling_probabilities(mesh: Mesh, rate: float, *, adaptivity: float = 0.5,
                           flat_floor: float = 0.25, guidance=None, regions=None, borders=None,
                           view: Optional[View] = None, boxes: Sequence[Box] = ()) -> np.ndarray:
    """The probability p(v) each vertex gets at base rate ``rate`` (docs/design.md §2.2), for inspection."""
    rate = params.number("rate", rate, 0, 1)
    job = make_job(mesh, target_vertices=1, mode="fast", adaptivity=adaptivity, flat_floor=flat_floor,
                   guidance=guidance, regions=regions, borders=borders, view=view, boxes=boxes)
    layout = mesh.feature_layout(regions, borders)
    return engine.sampling_probabilities(mesh.native, layout, float(rate), job)
