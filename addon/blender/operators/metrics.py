"""Metrics operators: measure the Hausdorff distance, write error colours, turntable (thesis 4.7)."""

from __future__ import annotations

import math
import time

import bpy
from bpy.props import FloatProperty, IntProperty
from mathutils import Euler, Vector

from ..analysis import metrics
from . import polls


def _mesh_object(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "MESH" else None


class TOPSTOC_OT_measure(bpy.types.Operator):
    """Measure the Hausdorff distance between the active mesh and its original, and its \
triangle quality (aspect ratio)"""

    bl_idname = "topstoc.measure"
    bl_label = "Measure"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.active_mesh_in_object_mode(context))

    def execute(self, context):
        obj = _mesh_object(context)
        try:
            figures = metrics.measure(obj)
        except metrics.MetricsError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        s = figures["symmetric"]
        p = figures["symmetric_percent"]
        self.report({"INFO"}, f"TopStoc: '{obj.name}' vs '{obj.topstoc.metrics.reference.name}': Hausdorff max "
                              f"{s['max']:.4g} ({p['max']:.3g} % of the diagonal), mean {s['mean']:.4g}, "
                              f"RMS {s['rms']:.4g}; aspect ratio mean {figures['aspect_mean']:.3f}, "
                              f"max {figures['aspect_max']:.3f}")
        return {"FINISHED"}


class TOPSTOC_OT_write_error_colors(bpy.types.Operator):
    """Write the per-face error colours to the colour attribute "TopStoc Error" (for renders and \
exports) and show it in Solid mode"""

    bl_idname = "topstoc.write_error_colors"
    bl_label = "Write Color Attribute"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh_in_object_mode(context)
        if reason is None and context.active_object.topstoc.metrics.state != "OK":
            reason = "Measure first: the colours show the measured error"
        return polls.refuse(cls, reason)

    def execute(self, context):
        obj = _mesh_object(context)
        try:
            # the overlay's colours: one scale for the objects shown together
            metrics.write_error_colors(obj, metrics.shared_error_percent(
                context.visible_objects, context.scene.topstoc.overlays.error_scale))
        except metrics.MetricsError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        space = context.space_data
        if space is not None and space.type == "VIEW_3D" and space.shading.type == "SOLID":
            space.shading.color_type = "VERTEX"  # Solid mode shows the active colour attribute
        self.report({"INFO"}, f"TopStoc: error colours written to '{metrics.ERROR_ATTRIBUTE}' on '{obj.name}'")
        return {"FINISHED"}


def spiral(t: float, turns: float = 2.0, low: float = math.radians(-15.0), high: float = math.radians(55.0),
           start: float = 0.0) -> tuple:
    """(azimuth, elevation) in radians of the turntable view at time ``t`` in [0, 1]: ``turns``
    full turns around the vertical axis while the elevation rises from ``low`` to ``high``."""
    t = min(1.0, max(0.0, t))
    smooth = t * t * (3.0 - 2.0 * t)  # ease in and out
    return start + turns * 2.0 * math.pi * smooth, low + (high - low) * smooth


def view_rotation(azimuth: float, elevation: float):
    """The 3D view rotation that looks at the pivot from ``azimuth`` (around Z, 0 = from the
    front, -Y) and ``elevation`` (above the horizon)."""
    return Euler((math.pi / 2.0 - elevation, 0.0, azimuth), "XYZ").to_quaternion()


def framing(obj) -> tuple:
    """World-space centre and radius of ``obj``'s bounding box."""
    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    center = sum(corners, Vector()) / 8.0
    radius = max((c - center).length for c in corners)
    return center, max(radius, 1e-6)


class TOPSTOC_OT_turntable(bpy.types.Operator):
    """Spiral the view twice around the active object, rising from below to above it \
(thesis 4.7); Esc stops and restores the view"""

    bl_idname = "topstoc.turntable"
    bl_label = "Turntable"

    duration: FloatProperty(name="Duration", default=8.0, min=0.5, max=120.0, subtype="TIME_ABSOLUTE",
                            unit="TIME_ABSOLUTE")
    turns: IntProperty(name="Turns", default=2, min=1, max=10)

    @classmethod
    def poll(cls, context):
        reason = "Select an object first" if context.active_object is None else polls.view_3d(context)
        if reason is None and context.space_data.region_3d is None:
            reason = "Run this from a 3D Viewport"
        return polls.refuse(cls, reason)

    def invoke(self, context, event):
        view = context.space_data.region_3d
        self.saved = (view.view_location.copy(), view.view_rotation.copy(), view.view_distance,
                      view.view_perspective)
        center, radius = framing(context.active_object)
        view.view_location = center
        view.view_distance = radius * 3.0
        if view.view_perspective == "CAMERA":
            view.view_perspective = "PERSP"
        self.start_time = time.perf_counter()
        self.start_azimuth = 0.0
        self.steps = 0
        self._apply(context, 0.0)
        self.timer = context.window_manager.event_timer_add(1.0 / 60.0, window=context.window)
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _apply(self, context, t: float) -> None:
        azimuth, elevation = spiral(t, float(self.turns), start=self.start_azimuth)
        context.space_data.region_3d.view_rotation = view_rotation(azimuth, elevation)
        context.area.tag_redraw()

    def _finish(self, context):
        context.window_manager.event_timer_remove(self.timer)
        view = context.space_data.region_3d
        view.view_location, view.view_rotation, view.view_distance, view.view_perspective = self.saved
        context.area.tag_redraw()

    def modal(self, context, event):
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            self._finish(context)
            return {"CANCELLED"}
        if event.type == "TIMER":
            t = (time.perf_counter() - self.start_time) / self.duration
            self.steps += 1
            if t >= 1.0:
                self._finish(context)
                return {"FINISHED"}
            self._apply(context, t)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        self.report({"ERROR"}, "the turntable runs in a 3D view (invoke it from the panel)")
        return {"CANCELLED"}


CLASSES = (TOPSTOC_OT_measure, TOPSTOC_OT_write_error_colors, TOPSTOC_OT_turntable)
