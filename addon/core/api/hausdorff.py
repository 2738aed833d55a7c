"""Hausdorff distance between two triangle meshes (docs/design.md §3; thesis 4.7.1, A.5).

>>> result = hausdorff((vertices, triangles), decimated)      # original first
>>> result.symmetric.max, result.forward.mean, result.diagonal
>>> colours = result.face_error                                # per triangle of the decimated mesh

Both surfaces are sampled with one spacing (Aspert et al. 2002, "MESH"; Metro): every vertex,
points along every edge no more than ``step`` apart, and the centroids of the n x n similar
sub-triangles of every triangle (n = ceil(longest edge / step)). The nearest point of the other
surface is found exactly through a bounding volume hierarchy, in parallel.

- ``max`` is bracketed, not only sampled: starting from the samples, the triangles whose
  distance bound (corner distances + the triangle's reach, the distance being 1-Lipschitz)
  exceeds the best distance found by more than ``max_tolerance`` are subdivided (the scheme of
  CGAL's ``bounded_error_Hausdorff_distance``), so ``max <= true max <= max_upper <= max * (1 +
  max_tolerance)``. ``max`` is a distance attained at ``max_point``; ``max_upper`` is the
  guarantee (error-bounded decimation holds its bound against it).
- ``mean``, ``rms`` and ``percentile`` are area-weighted over the
  face samples, i.e. integrals over the surface (``percentile=95`` gives the distance below
  which 95 % of the surface lies: a max that ignores small outliers).
- ``forward`` measures A against B (samples on A), ``backward`` B against A; ``symmetric``
  takes the larger of the two for each figure (the MESH convention).
- Per-element errors for colouring: ``vertex_error`` is the distance of each vertex of A (the
  original) to B; ``face_error`` the largest distance over each triangle of B (the decimated
  mesh) to A, so ``face_error.max() == backward.max``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..support import params
from ..support.native import engine
from ..support.errors import TopStocError

DEFAULT_SAMPLES = 1_000_000


@dataclass(frozen=True)
class Distance:
    """Summary figures of a distance over a surface."""

    max: float
    mean: float
    rms: float
    percentile: float   #: distance below which ``percentile_rank`` % of the area lies (NaN if not asked)
    max_upper: float = float("inf")  #: no point is farther than this (inf with max_tolerance=0)

    def scaled(self, factor: float) -> "Distance":
        return dataclasses.replace(self, max=self.max * factor, mean=self.mean * factor,
                                   rms=self.rms * factor, percentile=self.percentile * factor,
                                   max_upper=self.max_upper * factor)

    def as_dict(self) -> dict:
        return {"max": self.max, "max_upper": self.max_upper, "mean": self.mean, "rms": self.rms,
                "percentile": self.percentile}


@dataclass(frozen=True)
class OneSidedDistance(Distance):
    """Distance from the samples of one surface to the other surface."""

    samples: int = 0                                  #: number of sample points
    max_point: np.ndarray = None                      #: where the maximum was found (on the sampled surface)
    vertex_distance: np.ndarray = None                #: per vertex of the sampled surface (NaN if in no triangle)
    face_max: np.ndarray = None                       #: per triangle of the sampled surface

    def scaled(self, factor: float) -> "OneSidedDistance":
        base = Distance.scaled(self, factor)
        return dataclasses.replace(base, vertex_distance=self.vertex_distance * factor,
                                   face_max=self.face_max * factor)

    def rescaled_coordinates(self, factor: float) -> "OneSidedDistance":
        """Every figure and the max point in coordinates ``factor`` times larger."""
        return dataclasses.replace(self.scaled(factor), max_point=self.max_point * factor)


@dataclass(frozen=True)
class HausdorffResult:
    """Forward (A to B), backward (B to A) and symmetric distances, A being the original."""

    forward: OneSidedDistance
    backward: OneSidedDistance
    symmetric: Distance
    diagonal: float            #: bounding-box diagonal of A
    step: float                #: sample spacing used on both surfaces
    percentile_rank: float     #: the percentile asked for, in percent
    relative: bool = False     #: True when every distance is a fraction of ``diagonal``

    @property
    def vertex_error(self) -> np.ndarray:
        """Distance of each vertex of A (the original) to B, for colouring A."""
        return self.forward.vertex_distance

    @property
    def face_error(self) -> np.ndarray:
        """Largest distance over each triangle of B (the decimated mesh) to A, for colouring B."""
        return self.backward.face_max

    def to_relative(self) -> "HausdorffResult":
        """The same figures divided by the bounding-box diagonal of A."""
        if self.relative:
            return self
        factor = 1.0 / self.diagonal if self.diagonal > 0 else float("nan")
        return dataclasses.replace(self, forward=self.forward.scaled(factor),
                                   backward=self.backward.scaled(factor),
                                   symmetric=self.symmetric.scaled(factor), relative=True)

    def as_dict(self) -> dict:
        """The figures as plain numbers (the ``measure --json`` document, docs/design.md §6)."""
        return {
            "forward": self.forward.as_dict(),
            "backward": self.backward.as_dict(),
            "symmetric": self.symmetric.as_dict(),
            "diagonal": self.diagonal,
            "relative": self.relative,
            "step": self.step,
            "percentile_rank": self.percentile_rank,
            "samples": {"forward": self.forward.samples, "backward": self.backward.samples},
            "max_point": {"forward": self.forward.max_point.tolist(),
                          "backward": self.backward.max_point.tolist()},
        }


def _mesh_arrays(mesh, what: str):
    """(vertices, triangles) of a mesh given as a pair or as an object holding them."""
    if isinstance(mesh, tuple) and len(mesh) == 2:
        return mesh
    if hasattr(mesh, "vertices") and hasattr(mesh, "triangles"):
        return mesh.vertices, mesh.triangles
    raise TopStocError(f"{what} must be (vertices, triangles) or have .vertices and .triangles, "
                       f"got {type(mesh).__name__}")


def as_surface(mesh, what: str = "mesh"):
    """The engine's measurement surface for a mesh given as ``(vertices, triangles)`` or as any
    object with ``vertices`` and ``triangles`` (topstoc.Mesh, DecimateResult, io.MeshData)."""
    if isinstance(mesh, engine.Surface):
        return mesh
    if isinstance(mesh, tuple) and len(mesh) == 2:
        vertices, triangles = mesh
    elif hasattr(mesh, "vertices") and hasattr(mesh, "triangles"):
        vertices, triangles = mesh.vertices, mesh.triangles
    else:
        raise TopStocError(f"{what} must be (vertices, triangles) or have .vertices and .triangles, "
                           f"got {type(mesh).__name__}")
    try:
        return engine.Surface(vertices, triangles)
    except ValueError as error:
        raise TopStocError(f"{what}: {error}") from None


def _one_sided(raw: dict) -> OneSidedDistance:
    return OneSidedDistance(max=raw["max"], max_upper=raw["max_upper"], mean=raw["mean"], rms=raw["rms"],
                            percentile=raw["percentile"], samples=int(raw["samples"]),
                            max_point=raw["max_point"], vertex_distance=raw["vertex_distance"],
                            face_max=raw["face_max"])


def result_from_engine(raw: dict, percentile: float, relative: bool = False) -> HausdorffResult:
    """Wraps the engine's dictionary (used by the error-bounded search too)."""
    s = raw["symmetric"]
    result = HausdorffResult(forward=_one_sided(raw["forward"]), backward=_one_sided(raw["backward"]),
                             symmetric=Distance(max=s["max"], max_upper=s["max_upper"], mean=s["mean"], rms=s["rms"],
                                                percentile=s["percentile"]),
                             diagonal=raw["diagonal"], step=raw["step"], percentile_rank=percentile)
    return result.to_relative() if relative else result


def check_percentile(percentile: float) -> float:
    """Percentile rank in percent, (0, 100]; 0 skips it."""
    return params.number("percentile (0 skips it)", percentile, 0, 100)


def hausdorff(a, b, *, samples: Optional[int] = None, step: Optional[float] = None,
              percentile: float = 95.0, relative: bool = False, max_tolerance: float = 1e-3) -> HausdorffResult:
    """Hausdorff distance between ``a`` (the original) and ``b`` (its approximation).

    a, b: ``(vertices, triangles)`` arrays or objects with ``vertices`` and ``triangles``.
    samples: about how many samples to take on ``a`` (default 1,000,000); ``b`` is sampled with
    the same spacing. step: the spacing itself (overrides ``samples``). percentile: rank in
    percent for the k-th ranked distance (0 skips it). relative: divide every distance by the
    bounding-box diagonal of ``a``. max_tolerance: relative gap allowed between ``max`` and the
    guaranteed ``max_upper`` (0 = the sampled max only, fastest; ``max_upper`` is then inf).
    """
    if isinstance(max_tolerance, bool) or not isinstance(max_tolerance, (int, float, np.floating)) \
            or not 0 <= max_tolerance < float("inf"):
        raise TopStocError(f"max_tolerance must be a non-negative number, got {max_tolerance!r}")
    if samples is not None and step is not None:
        raise TopStocError("give samples or step, not both")
    if samples is None:
        samples = DEFAULT_SAMPLES
    samples = params.integer("samples", samples, 1, 2**62)
    if step is not None:
        step = params.number("step", step, 0, low_open=True)
    percentile = check_percentile(percentile)
    scale = 1.0
    if not isinstance(a, engine.Surface) and not isinstance(b, engine.Surface):
        # Products of coordinates overflow beyond ~1e77 and underflow below ~1e-77 (wrong closest
        # points, NaN means): measure in coordinates scaled by a power of two near the largest
        # one. Such a scaling is exact, so ordinary meshes give bit-identical figures.
        a, b = _mesh_arrays(a, "first mesh"), _mesh_arrays(b, "second mesh")
        largest = max(float(np.abs(np.asarray(a[0], dtype=np.float64)).max(initial=0.0)),
                      float(np.abs(np.asarray(b[0], dtype=np.float64)).max(initial=0.0)))
        if largest > 0 and np.isfinite(largest):
            scale = math.ldexp(1.0, math.frexp(largest)[1])
            a = (np.asarray(a[0], dtype=np.float64) / scale, a[1])
            b = (np.asarray(b[0], dtype=np.float64) / scale, b[1])
    surface_a = as_surface(a, "first mesh")
    surface_b = as_surface(b, "second mesh")
    raw = engine.hausdorff(surface_a, surface_b, samples=int(samples), step=float(step or 0.0) / scale,
                           percentile=percentile / 100.0, max_tolerance=float(max_tolerance))
    result = result_from_engine(raw, percentile)
    if scale != 1.0:
        result = dataclasses.replace(
            result, forward=result.forward.rescaled_coordinates(scale),
            backward=result.backward.rescaled_coordinates(scale),
            symmetric=result.symmetric.scaled(scale), diagonal=result.diagonal * scale, step=result.step * scale)
    return result.to_relative() if relative else result


def closest_points(mesh, points) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nearest point on ``mesh`` of each of ``points`` (k, 3): (distance, triangle, point)."""
    raw = engine.closest_points(as_surface(mesh), points)
    return raw["distance"], raw["triangle"], raw["point"]
