"""One decimation job: every parameter of a decimation, checked and resolved once (docs/design.md §1.5).

``make_job`` turns what a caller gives (a ratio or a count, the mode, guidance, view, boxes,
regions, borders, appearance attributes, a symmetry axis...) into a frozen ``DecimationJob``:
the mode resolved into placement and refinement, the target into the engine's vertex count,
every number range-checked (core/support/params.py) and every array in the engine's layout. The job is
what the engine binding reads (native/python/bind_decimate.cpp), field by field, once; the
public ``decimate``, the command line, the batch and the add-on all build one.
"""

from __future__ import annotations

import collections.abc
import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Optional, Sequence

import numpy as np

from ..support import params
from ..support.errors import TopStocError

if TYPE_CHECKING:  # for annotations only
    from .mesh import Mesh

DENSITY_MODES = ("off", "uniform", "adaptive", "euclidean")
PLACEMENTS = ("subsample", "filtered")
MODES = ("quality", "fast", "best")
#: quality mode: the collapses remove max(QUALITY_COLLAPSES, target / 4) vertices after a
#: stochastic first pass (the time then grows with the target, not with the mesh), which keeps
#: at least min(8 * target, 250,000) vertices, and on a mesh of up to 500,000 vertices at least
#: 125,000; they start from the
#: whole mesh when it has at most max(8 * QUALITY_COLLAPSES, 250,000) vertices (the lowest
#: error) or is sliver-heavy, up to 2M vertices (docs/design.md §2.10). QUALITY_REFINE only
#: marks the refinement as on: an explicit refine=f sizes the first pass as f times the target
#: instead of the budget.
QUALITY_REFINE = 1.0
QUALITY_COLLAPSES = 10_000
#: default weight of an attribute channel in the collapse cost (see decimate's attributes)
ATTRIBUTE_WEIGHT = 0.1
#: the most attribute channels the collapse cost takes
MAX_ATTRIBUTE_CHANNELS = 16
#: guidance at least this is a control point, always kept (painted colours have 8 bits: §2.2)
CONTROL_POINT = 1.0 - 1.0 / 256


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
        """The engine's view, every field checked (core/support/params.py): ParameterError names the field."""
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
        """(world_to_box, value) for the engine, checked (core/support/params.py)."""
        return (params.array("box world_to_box", self.world_to_box, (4, 4)),
                params.number("box value", self.value, -1, 1))


def engine_view(view) -> Optional[dict]:
    if view is None:
        return None
    if not isinstance(view, View):
        raise params.ParameterError(f"view must be a topstoc View, got {type(view).__name__}")
    return view.as_engine()


def engine_boxes(boxes) -> Optional[list]:
    if isinstance(boxes, (Box, str, bytes)) or not isinstance(boxes, collections.abc.Iterable):
        raise params.ParameterError(f"boxes must be a list of topstoc Box, got {type(boxes).__name__}")
    boxes = list(boxes)
    for i, box in enumerate(boxes):
        if not isinstance(box, Box):
            raise params.ParameterError(f"boxes[{i}] must be a topstoc Box, got {type(box).__name__}")
    return [box.as_engine() for box in boxes] or None


def guidance_values(mesh: Mesh, guidance) -> Optional[np.ndarray]:
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


def attribute_arrays(mesh: Mesh, attributes, weights):
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


def active_vertices(mesh: Mesh) -> int:
    report = mesh.native.report
    return report["input_vertices"] - report["isolated_vertices"]


def target_vertex_count(mesh: Mesh, ratio=None, vertices=None) -> int:
    """Vertex target from a ratio (of the vertices in triangles) or an explicit count."""
    active = active_vertices(mesh)
    if ratio is not None:
        return max(1, int(round(params.number("ratio", ratio, 0, 1, low_open=True) * active)))
    vertices = params.integer("target_vertices", vertices)
    if not 1 <= vertices <= active:
        raise TopStocError(f"vertex target {vertices} is outside [1, {active}] (vertices in triangles)")
    return vertices


@dataclass(frozen=True)
class Target:
    """What the caller asked for (exactly one of ratio, vertices, triangles, max_error) and the
    engine's vertex count it resolves to."""

    ratio: Optional[float] = None
    vertices: Optional[int] = None
    triangles: Optional[int] = None
    max_error: Optional[float] = None
    relative: bool = False           #: max_error is a fraction of the bounding-box diagonal
    #: the engine's vertex target: 1 under a triangle target, 0 under max_error (searched)
    vertex_count: int = 0

    @classmethod
    def count(cls, vertices: int) -> "Target":
        """An explicit vertex count, already checked (the error-bounded search's probes)."""
        return cls(vertices=vertices, vertex_count=vertices)


@dataclass(frozen=True, eq=False)
class DecimationJob:
    """A decimation, resolved and checked (see the module docs; ``decimate`` documents each field)."""

    target: Target
    mode: str = "quality"
    placement: str = "filtered"
    refine: float = QUALITY_REFINE
    refine_collapses: int = QUALITY_COLLAPSES
    seed: int = 0
    adaptivity: float = 0.5
    flat_floor: float = 0.25
    area_weighted: bool = False
    feature_angle: float = 0.0       #: radians
    density: str = "off"
    density_rings: int = 0
    density_ratio: float = 2.0
    density_epsilon: float = 0.0
    guidance: Optional[np.ndarray] = None           #: u per caller vertex, float64
    view: Optional[dict] = None                     #: View.as_engine()
    boxes: Optional[list] = None                    #: [Box.as_engine()]
    regions: object = None                          #: per caller triangle, as given (the layout is cached)
    borders: object = None                          #: (k, 2) vertex pairs, as given
    attributes: Optional[np.ndarray] = None         #: flat per corner and channel, float64
    attribute_weights: Optional[np.ndarray] = None  #: one per channel
    fast_path: int = 0
    max_repair_rounds: int = 200
    draft: bool = False
    symmetry: Optional[str] = None                  #: mirror axis "X", "Y", "Z" (core/api/symmetry.py)
    symmetry_tolerance: Optional[float] = None

    @property
    def large_fit(self) -> bool:
        """Whether large refined results are fitted to the input too (the engine's large_fit): mode "best"."""
        return self.mode == "best"

    @property
    def control_points(self) -> int:
        """Vertices the guidance keeps whatever the target."""
        return 0 if self.guidance is None else int(np.count_nonzero(self.guidance >= CONTROL_POINT))

    def at(self, vertices: int) -> "DecimationJob":
        """The same job at an explicit vertex count, without symmetry (a probe of the search)."""
        return dataclasses.replace(self, target=Target.count(vertices), symmetry=None)

    def plain(self) -> "DecimationJob":
        """The same job without the mirror (the draw a symmetric result starts from)."""
        return dataclasses.replace(self, symmetry=None)

    def parameters(self) -> dict:
        """What ``DecimateResult.parameters`` records: the target as asked and the resolved options."""
        t = self.target
        return dict(ratio=t.ratio, target_vertices=t.vertices, target_triangles=t.triangles, seed=self.seed,
                    adaptivity=self.adaptivity, flat_floor=self.flat_floor, area_weighted=self.area_weighted,
                    feature_angle=self.feature_angle, density=self.density, density_rings=self.density_rings,
                    density_ratio=self.density_ratio, density_epsilon=self.density_epsilon, mode=self.mode,
                    placement=self.placement, refine=self.refine, refine_collapses=self.refine_collapses,
                    attribute_channels=0 if self.attribute_weights is None else len(self.attribute_weights))


def one_target(ratio=None, vertices=None, triangles=None, max_error=None) -> None:
    """TopStocError unless exactly one of ratio, vertices, triangles, max_error is given."""
    given = [name for name, value in (("ratio", ratio), ("target_vertices", vertices),
                                      ("target_triangles", triangles), ("max_error", max_error)) if value is not None]
    if len(given) != 1:
        raise TopStocError("give exactly one target (ratio, target_vertices, target_triangles or max_error), "
                           f"got {given or 'none'}")


def make_target(mesh: Mesh, ratio=None, vertices=None, triangles=None, max_error=None,
                relative: bool = False) -> Target:
    """The Target for exactly one of ratio, vertices, triangles, max_error (TopStocError otherwise)."""
    one_target(ratio, vertices, triangles, max_error)
    if max_error is not None:
        return Target(max_error=params.number("max_error", max_error, 0), relative=bool(relative))
    if triangles is not None:
        count = params.integer("target_triangles", triangles)
        if not 1 <= count <= mesh.num_triangles:
            raise TopStocError(f"triangle target {count} is outside [1, {mesh.num_triangles}]")
        return Target(triangles=triangles, vertex_count=1)
    return Target(ratio=ratio, vertices=vertices, vertex_count=target_vertex_count(mesh, ratio, vertices))


def resolve_placement(mode: str, placement: Optional[str], symmetry=None) -> str:
    """The placement for a mode and the caller's choice (None: the mode's own). A mirrored job
    keeps input positions unless told otherwise (core/api/symmetry.py)."""
    if placement is None:
        placement = "subsample" if symmetry is not None or mode == "fast" else "filtered"
    if placement not in PLACEMENTS:
        raise TopStocError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
    return placement


def resolve_refine(mode: str, refine) -> tuple:
    """(refine, refine_collapses) for a mode and the caller's choice (None: the mode's own)."""
    if refine is None:
        return (QUALITY_REFINE, QUALITY_COLLAPSES) if mode != "fast" else (0.0, 0)
    wanted = "0 (off) or a factor of at least 1"
    refine = params.number("refine", refine, 0, expected=wanted)
    if 0 < refine < 1:
        params.number("refine", refine, 1, expected=wanted)  # raises
    return refine, 0


def make_job(mesh: Mesh, ratio=None, target_vertices=None, target_triangles=None, *, max_error=None,
             relative: bool = False, seed=0, adaptivity=0.5, flat_floor=0.25, area_weighted=False,
             feature_angle=0.0, density="off", density_rings=0, density_ratio=2.0, density_epsilon=0.0,
             guidance=None, regions=None, borders=None, view=None, boxes=(), mode="quality", placement=None,
             fast_path=None, max_repair_rounds=200, refine=None, attributes=None, attribute_weights=None,
             draft=False, symmetry=None, symmetry_tolerance=None) -> DecimationJob:
    """The DecimationJob for ``decimate``'s keywords (see there), every one checked here, once,
    in the order ``decimate`` always checked them; ``symmetry``: a mirror axis (core/api/symmetry.py).
    Raises TopStocError naming the bad one."""
    one_target(ratio, target_vertices, target_triangles, max_error)
    if mode not in MODES:
        raise TopStocError(f"mode must be one of {MODES}, got {mode!r}")
    if draft and (mode != "fast" or refine or max_error is not None):
        raise TopStocError("draft=True is for preview frames of the fast mode: give mode='fast', no refine "
                           "and no max_error")
    if density not in DENSITY_MODES:
        raise TopStocError(f"density must be one of {DENSITY_MODES}, got {density!r}")
    if symmetry is not None:
        from .symmetry import parse_axis

        symmetry = parse_axis(symmetry)
    placement = resolve_placement(mode, placement, symmetry)
    seed = params.seed(seed)
    refine, refine_collapses = resolve_refine(mode, refine)
    numbers = dict(adaptivity=params.number("adaptivity", adaptivity, 0, 1),
                   flat_floor=params.number("flat_floor", flat_floor, 0, 1),
                   feature_angle=params.number("feature_angle (radians)", feature_angle, 0, math.pi),
                   density_rings=params.integer("density_rings", density_rings, 0, 2**31 - 1),
                   density_ratio=params.number("density_ratio", density_ratio, 1),
                   density_epsilon=params.number("density_epsilon", density_epsilon, 0),
                   max_repair_rounds=params.integer("max_repair_rounds", max_repair_rounds, 0, 2**31 - 1))
    target = make_target(mesh, ratio, target_vertices, target_triangles, max_error, relative)
    u = guidance_values(mesh, guidance)
    values, weights = attribute_arrays(mesh, attributes, attribute_weights)
    return DecimationJob(
        target=target, mode=mode, placement=placement, refine=float(refine), refine_collapses=refine_collapses,
        seed=int(seed), area_weighted=bool(area_weighted), density=density, guidance=u,
        view=engine_view(view), boxes=engine_boxes(boxes), regions=regions, borders=borders, attributes=values,
        attribute_weights=weights, fast_path=0 if fast_path is None else int(bool(fast_path)), draft=bool(draft),
        symmetry=symmetry, symmetry_tolerance=symmetry_tolerance, **numbers)
