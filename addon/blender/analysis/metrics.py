"""The Metrics panel's data: Hausdorff distance to the original and triangle quality.

Both meshes are compared in their own (object-local) coordinates: a decimated copy has the
original's local frame whatever its placement, so it can stand next to the original (as
Multiview lays variants out) and still be measured against it. Per-face errors are kept on
the object (``obj.topstoc.metrics["face_error"]``, one value per loop triangle) for the error
overlay and can be written to a colour attribute, so they reach renders and exports.
"""

from __future__ import annotations

import time

import bpy
import numpy as np

from ...core.support.colors import error_colors
from ...core.api.guidance import srgb_to_linear
from ...core.api.hausdorff import hausdorff
from ...core.support.native import engine
from ...core.support.errors import TopStocError
from ..io import mesh_access, mesh_read
from ..preview import watch
from .failures import stored_failure

ERROR_ATTRIBUTE = "TopStoc Error"


class MetricsError(TopStocError):
    """A measurement that cannot run (message for the panel and the status bar)."""


def reference_of(obj):
    """The mesh ``obj`` is compared with: the chosen reference, else the object it came from."""
    chosen = obj.topstoc.metrics.reference
    if chosen is not None:
        return chosen
    source = bpy.data.objects.get(obj.get("topstoc_source", ""))
    return source if source is not None and source.type == "MESH" and source != obj else None


def _arrays(obj, role: str) -> mesh_read.MeshArrays:
    mesh_read.check_mesh_object(obj, MetricsError)
    arrays = mesh_read.read_mesh(obj.data)
    if len(arrays.triangles) == 0:
        raise MetricsError(f"{role} '{obj.name}' has no faces")
    return arrays


_current: dict = {}  # object name -> ((epoch, reference epoch, revision), still current?)


def is_current(obj) -> bool:
    """True when the stored figures still describe ``obj`` and its reference (positions too).

    The fingerprints are recomputed only after Blender reported a geometry change.
    """
    settings = obj.topstoc.metrics
    reference = settings.reference
    if settings.state != "OK" or reference is None:
        return False
    key = (watch.epoch(obj), watch.epoch(reference), settings.revision)
    memo = _current.get(obj.name_full)
    if memo is not None and memo[0] == key:
        return memo[1]
    current = (mesh_read.read_mesh(obj.data).digest() + mesh_read.read_mesh(reference.data).digest()) == settings.stamp
    _current[obj.name_full] = (key, current)
    return current


def measure(obj, reference=None, samples: int = None) -> dict:
    """Measures ``obj`` against ``reference`` (default: ``reference_of(obj)``); stores the figures.

    Returns the figures as a dictionary. Raises MetricsError with a clear message when there
    is nothing to compare with or a mesh is unusable; nothing is stored then but the message.
    """
    settings = obj.topstoc.metrics
    reference = reference if reference is not None else reference_of(obj)
    with stored_failure(settings, MetricsError):
        mesh_read.check_mesh_object(obj, MetricsError)
        if reference is None:
            raise MetricsError(f"'{obj.name}' has no original to compare with: pick one under Original")
        start = time.perf_counter()
        ours, theirs = _arrays(obj, "the mesh"), _arrays(reference, "the original")
        try:
            result = hausdorff((theirs.vertices, theirs.triangles), (ours.vertices, ours.triangles),
                               samples=int(samples or settings.samples))
            aspect = engine.aspect_ratio_stats(ours.vertices, ours.triangles)
        except ValueError as error:
            raise MetricsError(f"'{obj.name}' vs '{reference.name}': {error}") from None
        seconds = time.perf_counter() - start
    for side, distance in (("symmetric", result.symmetric), ("forward", result.forward),
                           ("backward", result.backward)):
        for figure in ("max", "mean", "rms"):
            setattr(settings, f"{side}_{figure}", float(getattr(distance, figure)))
    settings.diagonal = float(result.diagonal)
    settings.aspect_mean = float(aspect["mean"])
    settings.aspect_max = float(aspect["max"])
    settings.degenerate = int(aspect["degenerate"])
    settings["face_error"] = np.asarray(result.face_error, dtype=np.float64).tolist()
    settings.stamp = ours.digest() + theirs.digest()
    if settings.reference is None:
        settings.reference = reference
    settings.seconds = seconds
    settings.state, settings.message = "OK", ""
    settings.revision += 1
    return figures(obj)


def figures(obj) -> dict:
    """The stored figures: absolute and in % of the original's diagonal."""
    s = obj.topstoc.metrics
    out = {"diagonal": s.diagonal, "aspect_mean": s.aspect_mean, "aspect_max": s.aspect_max,
           "degenerate": s.degenerate}
    for side in ("symmetric", "forward", "backward"):
        values = {figure: getattr(s, f"{side}_{figure}") for figure in ("max", "mean", "rms")}
        out[side] = values
        out[side + "_percent"] = {k: (100.0 * v / s.diagonal if s.diagonal > 0 else float("nan"))
                                  for k, v in values.items()}
    return out


def face_errors(obj):
    """Per-loop-triangle errors stored by ``measure`` if they still fit the mesh, else None."""
    settings = obj.topstoc.metrics
    if settings.state != "OK" or "face_error" not in settings:
        return None
    values = np.asarray(settings["face_error"], dtype=np.float64)
    obj.data.calc_loop_triangles()
    return values if len(values) == len(obj.data.loop_triangles) else None


def error_scale(obj, percent: float) -> float:
    """The error shown red: ``percent`` of the original's diagonal, or the largest error if 0."""
    settings = obj.topstoc.metrics
    if percent > 0 and settings.diagonal > 0:
        return percent / 100.0 * settings.diagonal
    return settings.backward_max


def shared_error_percent(objects, percent: float) -> float:
    """The error shown red, in % of each original's diagonal, for objects shown together, so that
    one colour means one error on all of them and one legend holds: ``percent``, or (0) the
    largest error measured on any of them (0 when none is measured)."""
    if percent > 0:
        return percent
    largest = [100.0 * o.topstoc.metrics.backward_max / o.topstoc.metrics.diagonal for o in objects
               if o.type == "MESH" and o.topstoc.metrics.state == "OK" and o.topstoc.metrics.diagonal > 0]
    return max(largest, default=0.0)


def write_error_colors(obj, percent: float = 0.0) -> bpy.types.Attribute:
    """Writes the per-face errors as a face-corner colour attribute (``ERROR_ATTRIBUTE``).

    Every corner of a polygon takes the colour of the polygon's largest triangle error, on the
    overlay's scale. The attribute becomes the active and the render colour, so Solid mode
    (Attribute colour), Cook/Workbench renders and exporters that write vertex colours show it.
    """
    errors = face_errors(obj)
    if errors is None:
        raise MetricsError(f"'{obj.name}' has no up-to-date error measurement: press Measure first")
    mesh = obj.data
    arrays = mesh_read.read_mesh(mesh)
    polygon_error = np.zeros(len(mesh.polygons))
    np.maximum.at(polygon_error, arrays.triangle_polygon, errors)
    loop_polygon = np.repeat(np.arange(len(mesh.polygons)),
                             mesh_access.read_indices(mesh.polygons, "loop_total", len(mesh.polygons)))
    colors = error_colors(polygon_error, error_scale(obj, percent))[loop_polygon]
    attribute = mesh.color_attributes.get(ERROR_ATTRIBUTE)
    if attribute is not None and (attribute.domain != "CORNER" or attribute.data_type != "FLOAT_COLOR"):
        mesh.color_attributes.remove(attribute)
        attribute = None
    if attribute is None:
        attribute = mesh.color_attributes.new(ERROR_ATTRIBUTE, "FLOAT_COLOR", "CORNER")
    linear = colors.copy()
    linear[:, :3] = srgb_to_linear(colors[:, :3])  # float colours are stored scene-linear
    attribute.data.foreach_set("color", linear.ravel())
    mesh.color_attributes.active_color = attribute
    mesh.color_attributes.render_color_index = list(mesh.color_attributes).index(attribute)
    mesh.update()
    return attribute

