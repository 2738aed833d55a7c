"""Metrics panel: Hausdorff distance to the original, triangle quality, error colours, turntable."""

from __future__ import annotations

import bpy

from ..analysis import metrics
from .panels import _MeshPanel, _Panel, property_split, wrapped

SIDES = (("symmetric", "Symmetric"), ("forward", "Forward (original → this)"),
         ("backward", "Backward (this → original)"))


def distance_rows(obj) -> list:
    """(side label, [(figure label, absolute text, percent text)]) as the panel shows them."""
    figures = metrics.figures(obj)
    rows = []
    for side, label in SIDES:
        values, percent = figures[side], figures[side + "_percent"]
        rows.append((label, [(name.upper() if name == "rms" else name.capitalize(), f"{values[name]:.4g}",
                              f"{percent[name]:.3g} %") for name in ("max", "mean", "rms")]))
    return rows


class TOPSTOC_PT_metrics(_MeshPanel, bpy.types.Panel):
    bl_label = "Metrics"
    bl_order = 20

    def draw_mesh(self, context, layout, obj):
        settings = obj.topstoc.metrics
        property_split(layout)
        col = layout.column()
        col.prop(settings, "reference")
        if settings.reference is None:
            implied = metrics.reference_of(obj)
            wrapped(col, context, f"Compares with '{implied.name}'" if implied else
                    "Pick the original to compare with", "INFO")
        col.prop(settings, "samples")
        reference = settings.reference or metrics.reference_of(obj)
        if reference is not None:  # the basic information (thesis 4.7): vertex counts of both meshes
            wrapped(col, context, f"{len(reference.data.vertices):,} → {len(obj.data.vertices):,} vertices "
                                  f"({100.0 * len(obj.data.vertices) / max(1, len(reference.data.vertices)):.3g}\u00a0%)")
        layout.operator("topstoc.measure", icon="DRIVER_DISTANCE")
        if settings.state == "ERROR":
            layout.label(text=settings.message, icon="ERROR")
            return
        if settings.state != "OK":
            return
        if not metrics.is_current(obj):
            layout.label(text="A mesh changed since: measure again", icon="ERROR")
        layout.use_property_split = False
        for label, figures in distance_rows(obj):  # one line per figure: a column table cuts the values
            box = layout.box()
            wrapped(box, context, label)
            col = box.column(align=True)
            for name, absolute, percent in figures:
                col.label(text=f"{name}: {percent} ({absolute})")
        box = layout.box()
        wrapped(box, context, "Triangle shape (aspect ratio, 1 is equilateral)")
        col = box.column(align=True)
        col.label(text=f"Mean: {settings.aspect_mean:.3f}")
        col.label(text=f"Max: {settings.aspect_max:.3f}")
        if settings.degenerate:
            wrapped(box, context, f"{settings.degenerate} zero-area triangles", "ERROR")
        wrapped(layout, context, f"Original's diagonal: {settings.diagonal:.4g}")
        layout.label(text=f"Measured in {settings.seconds:.2f} s")


class TOPSTOC_PT_metrics_colors(_Panel, bpy.types.Panel):
    bl_label = "Colour by Error"
    bl_parent_id = "TOPSTOC_PT_metrics"

    def draw_header(self, context):
        self.layout.prop(context.scene.topstoc.overlays, "show_error", text="")

    def draw(self, context):
        layout = self.layout
        property_split(layout)
        show = context.scene.topstoc.overlays
        layout.active = show.show_error
        layout.prop(show, "error_scale")
        layout.operator("topstoc.write_error_colors", icon="GROUP_VCOL")


class TOPSTOC_PT_metrics_view(_Panel, bpy.types.Panel):
    bl_label = "View"
    bl_parent_id = "TOPSTOC_PT_metrics"

    def draw(self, context):
        self.layout.operator("topstoc.turntable", icon="CON_ROTLIKE")


CLASSES = (TOPSTOC_PT_metrics, TOPSTOC_PT_metrics_colors, TOPSTOC_PT_metrics_view)
