"""Screen-size targets: "good enough for an object covering N pixels" as a max-error target.

Game engines pick a LOD by the object's screen size: the projected diameter of its bounding
sphere over the screen height (Unreal's "screen size", Unity's LOD group percentages). A LOD
for that screen size may deviate from the original by at most ``pixel_error`` pixels. The
conversion used here:

- bounding sphere: centre = bounding-box centre, radius = largest vertex distance from it
  (deterministic; at most ~15 % above the minimal sphere's radius);
- screen size given in pixels: ``N`` = projected diameter of the sphere in pixels;
- or given by camera distance ``D`` (sphere centre to camera), vertical field of view ``fov``
  and vertical resolution ``R``: the sphere's silhouette on the view axis has angular radius
  ``asin(r / D)``, so with focal length ``f = (R / 2) / tan(fov / 2)`` pixels,
  ``N = 2 f tan(asin(r / D)) = R tan(asin(r / D)) / tan(fov / 2)``;
- world units per pixel ``w = 2 r / N`` (for the distance form this equals
  ``sqrt(D^2 - r^2) / f``: the scale at the depth of the silhouette); the max-error target is
  ``pixel_error * w``, fed to the error-bounded decimation (topstoc.core.api.error_bound).

The pixel figure is thus the symmetric Hausdorff error divided by ``w``. It is the on-axis,
first-order figure engines use: surface points nearer the camera than the silhouette (down
to depth ``D - r``) and points off the view axis project up to ``sqrt(D^2 - r^2) / (D - r)``
and ``1 / cos(fov / 2)`` times larger.

Small parts: a connected part whose bounding-box diagonal projects below ``prune_pixels`` can
be dropped from a LOD (topstoc.core.batch.prune); its world size is ``prune_pixels * w``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np
from ..support.errors import TopStocError

DEFAULT_FOV_DEGREES = 60.0
DEFAULT_RESOLUTION = 1080
DEFAULT_PIXEL_ERROR = 1.0


@dataclass(frozen=True)
class ScreenTarget:
    """A screen-size target turned into world units (the object's own units)."""

    pixels: float            #: projected diameter of the bounding sphere, in pixels
    pixel_error: float       #: allowed deviation, in pixels
    radius: float            #: bounding-sphere radius
    world_per_pixel: float   #: world units one pixel spans at this screen size
    distance: Optional[float] = None  #: camera distance, when the target was given by one

    @property
    def max_error(self) -> float:
        """The allowed deviation in world units."""
        return self.pixel_error * self.world_per_pixel

    def to_pixels(self, world: float) -> float:
        """A world-space length (e.g. a measured Hausdorff error) in pixels."""
        return float(world) / self.world_per_pixel

    def as_dict(self) -> dict:
        return {"pixels": self.pixels, "pixel_error": self.pixel_error, "radius": self.radius,
                "world_per_pixel": self.world_per_pixel, "max_error": self.max_error,
                "distance": self.distance}


def bounding_sphere(vertices) -> tuple:
    """(centre, radius): bounding-box centre and the largest vertex distance from it."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if len(v) == 0:
        raise TopStocError("a bounding sphere needs at least one vertex")
    if not np.isfinite(v).all():
        raise TopStocError("vertex coordinates must be finite")
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    radius = float(np.sqrt(((v - centre) ** 2).sum(axis=1).max()))
    return centre, radius


def _positive(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
            or not math.isfinite(value) or value <= 0:
        raise TopStocError(f"{name} must be a positive number, got {value!r}")
    return float(value)


def projected_pixels(radius: float, distance: float, fov_degrees: float = DEFAULT_FOV_DEGREES,
                     resolution: int = DEFAULT_RESOLUTION) -> float:
    """Projected diameter in pixels of a sphere of ``radius`` centred ``distance`` ahead of a
    perspective camera with vertical field of view ``fov_degrees`` and ``resolution`` rows."""
    radius = _positive("radius", radius)
    distance = _positive("distance", distance)
    fov = _positive("fov", fov_degrees)
    if fov >= 180:
        raise TopStocError(f"fov must lie in (0, 180) degrees, got {fov_degrees!r}")
    resolution = _positive("resolution", resolution)
    if distance <= radius:
        raise TopStocError(f"distance {distance:g} must exceed the bounding-sphere radius {radius:g} "
                           "(the camera would be inside the object)")
    return resolution * math.tan(math.asin(radius / distance)) / math.tan(math.radians(fov) / 2)


def screen_target(vertices, *, pixels: float = None, distance: float = None,
                  fov_degrees: float = DEFAULT_FOV_DEGREES, resolution: int = DEFAULT_RESOLUTION,
                  pixel_error: float = DEFAULT_PIXEL_ERROR) -> ScreenTarget:
    """The world-space target for an object (its ``vertices``) covering ``pixels`` pixels, or
    seen from ``distance`` with ``fov_degrees`` / ``resolution``; exactly one of the two."""
    if (pixels is None) == (distance is None):
        raise TopStocError("give exactly one of pixels (projected diameter) or distance")
    pixel_error = _positive("pixel_error", pixel_error)
    _, radius = bounding_sphere(vertices)
    if radius == 0:
        raise TopStocError("the object has no extent (all vertices coincide)")
    if distance is not None:
        distance = _positive("distance", distance)
        pixels = projected_pixels(radius, distance, fov_degrees, resolution)
    pixels = _positive("pixels", pixels)
    return ScreenTarget(pixels=pixels, pixel_error=pixel_error, radius=radius,
                        world_per_pixel=2.0 * radius / pixels, distance=distance)
