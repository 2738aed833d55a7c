"""TopStoc decimation on numpy arrays (thesis 4.1, 4.3-4.6; docs/design.md §2).

The output's vertices are input vertices (or, with ``placement="filtered"``, points close to
them); each output triangle comes from one input triangle and keeps its orientation. The
topology of every manifold component (components, genus, boundary loops) is kept; where plain
clustering would break it, samples are added and the result says how many.

Two modes (``mode=``): ``"quality"`` (the default) runs TopStoc to a few times the target,
then quadric-ordered edge collapses thin it to the target (``refine``, filtered placement);
``"fast"`` is the thesis' plain TopStoc (what the live preview shows while the slider moves).

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

import collections.abc
import dataclasses
import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional, Sequence

import numpy as np

from . import params
from .native import engine
from .errors import TopStocError

if TYPE_CHECKING:  # for annotations only: mesh.py imports this module
    from .mesh import Mesh

DENSITY_MODES = ("off", "uniform", "adaptive", "euclidean")
PLACEMENTS = ("subsample", "filtered")
MODES = ("quality", "fast")
#: quality mode: the collapses remove at most max(QUALITY_COLLAPSES, target / 4) vertices
#: after a stochastic first pass (the time then grows with the target, not with the mesh), and
#: start from the whole mesh when it has at most 5 * QUALITY_COLLAPSES vertices (the lowest
#: error; docs/design.md §2.10). QUALITY_REFINE only marks the refinement as on: an explicit
#: refine=f sizes the first pass as f times the target instead of the budget.
QUALITY_REFINE = 1.0
QUALITY_COLLAPSES = 10_000
#: default weight of an attribute channel in the collapse cost (see decimate's attributes)
ATTRIBUTE_WEIGHT = 0.1
#: the most attribute channels the collapse cost takes
MAX_ATTRIBUTE_CHANNELS = 16
#: how far over the target a result may land before it counts as over budget
BUDGET_TOLERANCE = 0.01


@dataclass
class View:
    """View-dependent guidance (thesis 4.4).

    Perspective views give the camera position ``eye``; orthographic views the viewing
    ``direction``. Back-facing vertices get ``p *= back_ratio``; vertices whose normal is within
    the silhouette band ``|n.v| <= (1 - cos(silhouette_angle)) / 2`` are kept, with a linear
    fall-off over ``silhouette_falloff`` (in units of ``|n.v|``). With a ``view_projection``
    matrix (world to clip, 4x4, row-major as numpy prints it), vertices outside the frustum get
    at most ``outside_probability``.
    """

    eye: Optional[Sequence[float]] = None
    direction: Optional[Sequence[float]] = None
    back_ratio: float = 0.25
    silhouette_angle: float = math.radians(20.0)
    silhouette_falloff: float = 0.1
    view_projection: Optional[np.ndarray] = None
    outside_probability: float = 0.0

    def __post_init__(self):
        self.as_engine()  # refuse bad fields where the view is made (and again where it is used)

    def as_engine(self) -> dict:
        """The engine's view, every field checked (core/params.py): ParameterError names the field."""
        if (self.eye is None) == (self.direction is None):
            raise params.ParameterError("a view needs exactly one of eye (perspective) or direction (orthographic)")
        d = {
            "perspective": self.eye is not None,
            "back_ratio": params.number("view back_ratio", self.back_ratio, 0, 1),
            "silhouette_angle": params.number("view silhouette_angle (radians)", self.silhouette_angle, 0, math.pi),
            "silhouette_falloff": params.number("view silhouette_falloff", self.silhouette_falloff, 0),
            "outside_probability": params.number("view outside_probability", self.outside_probability, 0, 1),
        }
        if self.eye is not None:
            d["eye"] = params.array("view eye", self.eye, (3,))
        else:
            d["direction"] = params.array("view direction", self.direction, (3,), nonzero=True)
        if self.view_projection is not None:
            d["view_projection"] = params.array("view view_projection", self.view_projection, (4, 4))
        return d


@dataclass
class Box:
    """A box region (thesis 4.6): vertices inside take guidance ``value``.

    ``world_to_box`` maps world coordinates into the box's frame, where the box is [-1, 1]^3
    (a Blender cube empty of size 1 has exactly this frame: pass its inverted world matrix).
    """

    world_to_box: np.ndarray
    value: float

    def __post_init__(self):
        self.as_engine()

    @classmethod
    def from_center_size(cls, center, half_size, value: float) -> "Box":
        """Axis-aligned box from its centre and half extents (each > 0)."""
        center = params.array("box center", center, (3,))
        half = params.array("box half_size", half_size, (3,))
        if np.any(half <= 0):
            raise params.ParameterError(f"box half sizes must be positive, got {half.tolist()}")
        m = np.eye(4)
        m[:3, :3] = np.diag(1.0 / half)
        m[:3, 3] = -center / half
        return cls(m, value)

    def as_engine(self):
        """(world_to_box, value) for the engine, checked (core/params.py)."""
        return (params.array("box world_to_box", self.world_to_box, (4, 4)),
                params.number("box value", self.value, -1, 1))


def _engine_view(view) -> Optional[dict]:
    if view is None:
        return None
    if not isinstance(view, View):
        raise params.ParameterError(f"view must be a topstoc View, got {type(view).__name__}")
    return view.as_engine()


def _engine_boxes(boxes) -> Optional[list]:
    if isinstance(boxes, (Box, str, bytes)) or not isinstance(boxes, collections.abc.Iterable):
        raise params.ParameterError(f"boxes must be a list of topstoc Box, got {type(boxes).__name__}")
    boxes = list(boxes)
    for i, box in enumerate(boxes):
        if not isinstance(box, Box):
            raise params.ParameterError(f"boxes[{i}] must be a topstoc Box, got {type(box).__name__}")
    return [box.as_engine() for box in boxes] or None


@dataclass(frozen=True)
class DecimateStats:
    """How a decimation went."""

    target_vertices: int        #: what was asked for (vertex count)
    selected: int               #: samples drawn before repairs
    forced: int                 #: corners and control points among them
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
    output_vertices: int = 0    #: vertices of the result
    #: the final check of the output against the input's components (manifold, orientation,
    #: components, Euler characteristic, boundary loops, duplicates, finite coordinates; see
    #: native verify.hpp). All zero except ``zero_area`` whenever ``topology_kept`` is True: a
    #: violation the repairs did not report raises instead of returning.
    output_check: dict = field(default_factory=dict)
    #: the final check ran; False only for a draft (``decimate(draft=True)``), which leaves it out
    output_checked: bool = True

    @property
    def over_budget(self) -> int:
        """Vertices above the target when the result misses it by more than 1 % (else 0)."""
        excess = self.output_vertices - self.target_vertices
        return excess if excess > max(1, BUDGET_TOLERANCE * self.target_vertices) else 0

    @property
    def over_budget_reason(self) -> str:
        """Why the result is over budget: "" (it is not), "control points" (the vertices that
        must stay, u = 1 and border corners, outnumber the target) or "topology" (samples the
        topology needed)."""
        if not self.over_budget:
            return ""
        return "control points" if self.forced >= self.target_vertices else "topology"

    @property
    def topology_kept(self) -> Optional[bool]:
        """True when no topological issue remained (see issues_remaining) and the final check
        confirmed it; None for a draft, whose output was not re-checked."""
        if not self.output_checked:
            return None
        return not any(v for k, v in self.issues_remaining.items() if k != "sliver") and \
            not any(v for k, v in self.output_check.items() if k != "zero_area")


@dataclass(frozen=True)
class DecimateResult:
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
    #: with ``max_error``: how the error-bounded search went (see topstoc.core.error_bound)
    error_bound: Optional[object] = None

    @property
    def num_vertices(self) -> int:
        return len(self.vertices)

    @property
    def num_triangles(self) -> int:
        return len(self.triangles)

    def aspect_ratio(self) -> dict:
        """Triangle aspect ratio (thesis eq. 4.2): mean, max and count of degenerate ones."""
        return engine.aspect_ratio_stats(self.vertices, self.triangles)


def _result(raw: dict, parameters: dict) -> DecimateResult:
    stats = DecimateStats(**{f.name: raw[f.name] for f in dataclasses.fields(DecimateStats)  # same names
                             if f.name != "output_vertices"}, output_vertices=len(raw["vertices"]))
    return DecimateResult(vertices=raw["vertices"], triangles=raw["triangles"], kept=raw["kept"],
                          face_source=raw["face_source"], corner_source=raw["corner_source"],
                          labels=raw["labels"], samples=raw["samples"], stats=stats,
                          parameters=parameters)


def _guidance(mesh: Mesh, guidance) -> Optional[np.ndarray]:
    if guidance is None:
        return None
    u = params.real_array("guidance", guidance, "one number in [-1, 1] per vertex", booleans=True)
    if u.shape != (mesh.native.report["input_vertices"],):
        raise TopStocError(f"guidance must hold one value per vertex ({mesh.vertices.shape[0]}), "
                           f"got shape {u.shape}")
    bad = np.flatnonzero(~np.isfinite(u) | (u < -1) | (u > 1))
    if len(bad):
        raise TopStocError(f"guidance of vertex {bad[0]} is {u[bad[0]]}; it must lie in [-1, 1]")
    return u


def _attributes(mesh: Mesh, attributes, weights):
    """Attributes for the collapse cost as (flat per-corner values, per-channel weights), or
    (None, None). attributes: (n, k) per vertex or (m, 3, k) per corner of the caller's
    triangles; weights: a number or one per channel."""
    if attributes is None:
        if weights is not None:
            raise TopStocError("attribute_weights given without attributes")
        return None, None
    values = np.asarray(attributes)
    if values.dtype.kind not in "fiu":
        raise TopStocError(f"attributes must be a float array, got {values.dtype}")
    values = values.astype(np.float64)
    n, m = mesh.native.report["input_vertices"], len(mesh.triangles)
    if values.ndim == 1 and len(values) == n:
        values = values[:, None]
    if values.ndim == 2 and values.shape[0] == n:
        values = values[mesh.triangles]                     # per vertex -> per corner
    elif not (values.ndim == 3 and values.shape[:2] == (m, 3)):
        raise TopStocError(f"attributes must have shape (n, k) per vertex ({n} vertices) or (m, 3, k) per "
                           f"corner ({m} triangles), got {values.shape}")
    channels = values.shape[2]
    if not 1 <= channels <= MAX_ATTRIBUTE_CHANNELS:
        raise TopStocError(f"attributes must have 1 to {MAX_ATTRIBUTE_CHANNELS} channels, got {channels}")
    bad = np.argwhere(~np.isfinite(values))
    if len(bad):
        t, c, k = bad[0]
        raise TopStocError(f"attribute {k} of corner {c} of triangle {t} is {values[t, c, k]}; it must be finite")
    w = np.asarray(ATTRIBUTE_WEIGHT if weights is None else weights, dtype=np.float64)
    if w.ndim == 0:
        w = np.full(channels, float(w))
    if w.shape != (channels,):
        raise TopStocError(f"attribute_weights must be a number or one per channel ({channels}), got shape {w.shape}")
    if not np.all(np.isfinite(w) & (w >= 0)):
        raise TopStocError(f"attribute_weights must be finite and >= 0, got {w}")
    return np.ascontiguousarray(values).ravel(), np.ascontiguousarray(w)


def _active_vertices(mesh: Mesh) -> int:
    report = mesh.native.report
    return report["input_vertices"] - report["isolated_vertices"]


def target_vertex_count(mesh: Mesh, ratio=None, vertices=None) -> int:
    """Vertex target from a ratio (of the vertices in triangles) or an explicit count."""
    active = _active_vertices(mesh)
    if ratio is not None:
        return max(1, int(round(params.number("ratio", ratio, 0, 1, low_open=True) * active)))
    vertices = params.integer("target_vertices", vertices)
    if not 1 <= vertices <= active:
        raise TopStocError(f"vertex target {vertices} is outside [1, {active}] (vertices in triangles)")
    return vertices


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
    (see QUALITY_COLLAPSES); "fast": the thesis' TopStoc, placement "subsample", no refinement.
    placement and refine, when given, override what the mode sets.
    placement: "subsample" keeps the first pass's input positions, "filtered" moves surface
    vertices to the quadric-optimal point of their cluster (borders stay). In quality mode the
    collapses themselves place a vertex joining two free vertices at the quadric optimum either
    way; placement only decides the final re-fit.
    refine: None = the mode's own (quality: the first pass keeps the target plus
    max(QUALITY_COLLAPSES, target / 4) vertices, or the whole mesh up to 5 * QUALITY_COLLAPSES;
    fast: 0). 0 = off (fastest). f >= 1: TopStoc keeps f times the target (so refine=1 leaves
    the collapses almost nothing to do), then edge collapses ordered by quadric error against
    the input thin it to the target (topology and borders kept, painted regions keeping their
    share of the budget). Lower error at a higher cost.
    attributes: UVs, colours, normals... that should survive the collapses: (n, k) per vertex
    or (m, 3, k) per corner of the caller's triangles (per corner for UVs with seams). They
    enter the collapse cost as generalised quadrics (docs/design.md §2.10): with weight w, a
    difference d in a channel costs as much as moving the surface by w * d bounding-box
    diagonals. attribute_weights: a number or one per channel (default ATTRIBUTE_WEIGHT).
    Only the refinement (quality mode) uses them; output attributes still come from the input
    through corner_source (topstoc.core.attributes interpolates those of moved vertices).
    max_error: the fewest vertices whose symmetric Hausdorff error stays within this bound
    (absolute, or a fraction of the bounding-box diagonal with ``relative=True``), found by a
    search over re-decimations with the same seed; ``result.error_bound`` tells how it went.
    draft: a live-preview frame (fast mode only): the same vertices and triangles, without
    face_source, corner_source and labels (empty arrays) and without the final output check
    (``stats.output_checked`` False, ``stats.topology_kept`` None). The partition checks and
    repairs still run; what a draft skips is the independent re-check, so show drafts while a
    slider moves and decimate in full for what is kept.
    """
    vertices = _renamed("vertices", vertices, "target_vertices", target_vertices)  # the counts asked for
    triangles = _renamed("triangles", triangles, "target_triangles", target_triangles)
    given = [name for name, value in (("ratio", ratio), ("target_vertices", vertices),
                                      ("target_triangles", triangles), ("max_error", max_error)) if value is not None]
    if len(given) != 1:
        raise TopStocError("give exactly one target (ratio, target_vertices, target_triangles or max_error), "
                           f"got {given or 'none'}")
    if mode not in MODES:
        raise TopStocError(f"mode must be one of {MODES}, got {mode!r}")
    if draft and (mode != "fast" or refine or max_error is not None):
        raise TopStocError("draft=True is for preview frames of the fast mode: give mode='fast', no refine "
                           "and no max_error")
    if placement is None:
        placement = "filtered" if mode == "quality" else "subsample"
    refine_asked = refine  # the error-bounded search re-decimates with the caller's own choice
    refine_collapses = 0
    if refine is None:
        refine = QUALITY_REFINE if mode == "quality" else 0.0
        refine_collapses = QUALITY_COLLAPSES if mode == "quality" else 0
    if max_error is not None:  # error-bounded: a search over vertex targets (error_bound.py)
        from .error_bound import search_vertex_count

        def decimate_at(count: int) -> DecimateResult:
            return decimate(mesh, target_vertices=count, seed=seed, adaptivity=adaptivity, flat_floor=flat_floor,
                            area_weighted=area_weighted, feature_angle=feature_angle, density=density, density_rings=density_rings, density_ratio=density_ratio,
                            density_epsilon=density_epsilon, guidance=guidance, regions=regions,
                            borders=borders, view=view, boxes=boxes, mode=mode, placement=placement,
                            fast_path=fast_path, max_repair_rounds=max_repair_rounds, refine=refine_asked,
                            attributes=attributes, attribute_weights=attribute_weights)

        result, report = search_vertex_count(mesh, max_error, decimate_at, relative=relative)
        return dataclasses.replace(result, error_bound=report,
                                   parameters={**result.parameters, "max_error": max_error, "relative": relative})
    if density not in DENSITY_MODES:
        raise TopStocError(f"density must be one of {DENSITY_MODES}, got {density!r}")
    if placement not in PLACEMENTS:
        raise TopStocError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
    seed = params.seed(seed)
    refine_wanted = "0 (off) or a factor of at least 1"
    refine = params.number("refine", refine, 0, expected=refine_wanted)
    if 0 < refine < 1:
        refine = params.number("refine", refine, 1, expected=refine_wanted)  # raises
    adaptivity = params.number("adaptivity", adaptivity, 0, 1)
    flat_floor = params.number("flat_floor", flat_floor, 0, 1)
    feature_angle = params.number("feature_angle (radians)", feature_angle, 0, math.pi)
    density_rings = params.integer("density_rings", density_rings, 0, 2**31 - 1)
    density_ratio = params.number("density_ratio", density_ratio, 1)
    density_epsilon = params.number("density_epsilon", density_epsilon, 0)
    max_repair_rounds = params.integer("max_repair_rounds", max_repair_rounds, 0, 2**31 - 1)
    target_triangles = 0
    if triangles is not None:
        target_triangles = params.integer("target_triangles", triangles)
        if not 1 <= target_triangles <= mesh.num_triangles:
            raise TopStocError(f"triangle target {target_triangles} is outside [1, {mesh.num_triangles}]")
        target = 1
    else:
        target = target_vertex_count(mesh, ratio, vertices)
    u = _guidance(mesh, guidance)
    attribute_values, attribute_weights = _attributes(mesh, attributes, attribute_weights)
    layout, floods = mesh.layout_and_floods(regions, borders, feature_angle)
    parameters = dict(ratio=ratio, target_vertices=vertices, target_triangles=triangles, seed=int(seed),
                      adaptivity=adaptivity, flat_floor=flat_floor, area_weighted=bool(area_weighted),
                      feature_angle=float(feature_angle), density=density,
                      density_rings=density_rings, density_ratio=density_ratio,
                      density_epsilon=density_epsilon, mode=mode, placement=placement, refine=float(refine),
                      refine_collapses=refine_collapses,
                      attribute_channels=0 if attribute_weights is None else len(attribute_weights))
    raw = engine.decimate(
        mesh.native, layout, target_vertices=target, target_triangles=target_triangles,
        seed=int(seed), adaptivity=float(adaptivity), flat_floor=float(flat_floor),
        area_weighted=bool(area_weighted), guidance=u,
        density=density, density_rings=int(density_rings), density_ratio=float(density_ratio),
        density_epsilon=float(density_epsilon),
        view=_engine_view(view), boxes=_engine_boxes(boxes), placement=placement,
        fast_path=0 if fast_path is None else int(bool(fast_path)),
        max_repair_rounds=int(max_repair_rounds), refine=float(refine), refine_collapses=int(refine_collapses),
        attributes=attribute_values, attribute_weights=attribute_weights, flood_caches=floods, draft=bool(draft))
    return _result(raw, parameters)


def decimate_with_samples(mesh: Mesh, samples, *, regions=None, borders=None, feature_angle: float = 0.0,
                          placement: str = "subsample", refine_vertices: int = 0, refine_triangles: int = 0,
                          guidance=None, attributes=None, attribute_weights=None) -> DecimateResult:
    """Re-creates a decimation from ``DecimateResult.samples`` (thesis 4.1.3).

    With the same mesh, regions, borders, feature angle and placement the output is identical.
    A refined result (``refine`` > 0) also needs ``refine_vertices=result.stats.refine_vertices``,
    ``refine_triangles=result.stats.refine_triangles`` and the same ``guidance`` and
    ``attributes``.
    """
    if placement not in PLACEMENTS:
        raise TopStocError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
    samples = np.asarray(samples)
    if samples.ndim != 1 or samples.dtype.kind not in "iu":
        raise TopStocError(f"samples must be a 1-D integer array, got {samples.dtype} {samples.shape}")
    refine_vertices = params.integer("refine_vertices", refine_vertices, 0, 2**31 - 1)
    refine_triangles = params.integer("refine_triangles", refine_triangles, 0, 2**31 - 1)
    feature_angle = params.number("feature_angle (radians)", feature_angle, 0, math.pi)
    attribute_values, attribute_weights = _attributes(mesh, attributes, attribute_weights)
    layout = mesh.feature_layout(regions, borders, feature_angle)
    raw = engine.decimate_with_samples(mesh.native, layout, samples, placement=placement,
                                       refine_vertices=int(refine_vertices), guidance=_guidance(mesh, guidance),
                                       refine_triangles=int(refine_triangles), attributes=attribute_values,
                                       attribute_weights=attribute_weights)
    return _result(raw, dict(samples=len(samples), placement=placement, feature_angle=feature_angle,
                             refine_vertices=int(refine_vertices), refine_triangles=int(refine_triangles)))


def sampling_probabilities(mesh: Mesh, rate: float, *, adaptivity: float = 0.5,
                           flat_floor: float = 0.25, guidance=None, regions=None, borders=None,
                           view: Optional[View] = None, boxes: Sequence[Box] = ()) -> np.ndarray:
    """The probability p(v) each vertex gets at base rate ``rate`` (docs/design.md §2.2), for inspection."""
    rate = params.number("rate", rate, 0, 1)
    adaptivity = params.number("adaptivity", adaptivity, 0, 1)
    flat_floor = params.number("flat_floor", flat_floor, 0, 1)
    layout = mesh.feature_layout(regions, borders)
    return engine.sampling_probabilities(
        mesh.native, layout, float(rate), adaptivity=float(adaptivity), flat_floor=float(flat_floor),
        guidance=_guidance(mesh, guidance), view=_engine_view(view), boxes=_engine_boxes(boxes))
