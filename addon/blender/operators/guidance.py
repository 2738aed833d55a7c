"""Guidance editing: the painting layer and palette, direct selection (thesis fig. 4.13), boxes."""

from __future__ import annotations

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty

from ...core.api import guidance as rules
from ..io import mesh_access, mesh_read, mesh_attributes, edge_flags
from . import polls

LEVELS = [("KEEP", "Keep", "Always keep (u = 1)"), ("MORE", "More", "More detail (u = 0.5)"),
          ("NEUTRAL", "Neutral", "Follow the global target (u = 0)"),
          ("LESS", "Less", "Less detail (u = -0.5)"), ("DROP", "Drop", "Never sample (u = -1)"),
          ("CUSTOM", "Custom", "The value below")]
PALETTE_NAME = "TopStoc Guidance"


def ensure_layer(obj) -> bpy.types.Attribute:
    """The object's guidance colour attribute, created grey (neutral) on the vertices if missing."""
    mesh = obj.data
    name = obj.topstoc.color_attribute
    attribute = mesh.color_attributes.get(name)
    if attribute is None:
        attribute = mesh.color_attributes.new(name, "FLOAT_COLOR", "POINT")
        grey = rules.srgb_to_linear(rules.guidance_color(np.zeros(len(mesh.vertices))))
        grey[:, 3] = 1.0
        attribute.data.foreach_set("color", grey.astype(np.float32).ravel())
    mesh.color_attributes.active_color = attribute
    obj.topstoc.use_color = True
    return attribute


def write_guidance(obj, vertex_mask: np.ndarray, polygon_mask: np.ndarray, u: float) -> int:
    """Sets guidance ``u`` on the masked vertices (or the corners of the masked polygons)."""
    mesh = obj.data
    attribute = ensure_layer(obj)
    if attribute.domain == "POINT":
        count, mask = len(mesh.vertices), vertex_mask
    else:
        count = len(mesh.loops)
        loop_vertex = mesh_read.corner_vertices(mesh)
        if polygon_mask is not None:
            loop_polygon = np.repeat(np.arange(len(mesh.polygons)),
                                     mesh_access.read_indices(mesh.polygons, "loop_total", len(mesh.polygons)))
            mask = polygon_mask[loop_polygon]
        else:
            mask = vertex_mask[loop_vertex]
    values, key = mesh_attributes.read_attribute(attribute, count)
    color = rules.guidance_color(u)
    if key == "color":
        color = np.r_[rules.srgb_to_linear(color[:3]), 1.0]
    values = values.astype(np.float32)
    values[mask] = color
    attribute.data.foreach_set(key, values.ravel())
    mesh.update()
    return int(mask.sum())


class TOPSTOC_OT_add_guidance_layer(bpy.types.Operator):
    """Create the guidance colour attribute (grey = neutral) and the guidance palette"""

    bl_idname = "topstoc.add_guidance_layer"
    bl_label = "Add Guidance Layer"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh(context)
        if reason is None and context.mode == "EDIT_MESH":
            reason = "Switch to Object Mode first"
        return polls.refuse(cls, reason)

    def execute(self, context):
        ensure_layer(context.object)
        palette = bpy.data.palettes.get(PALETTE_NAME) or bpy.data.palettes.new(PALETTE_NAME)
        if len(palette.colors) == 0:
            for name in ("KEEP", "MORE", "NEUTRAL", "LESS", "DROP"):
                palette.colors.new().color = rules.guidance_color(rules.GUIDANCE_LEVELS[name])[:3]
        paint = context.tool_settings.vertex_paint
        if paint is not None:
            paint.palette = palette
        self.report({"INFO"}, f"Guidance layer '{context.object.topstoc.color_attribute}' ready: paint orange "
                              "for more detail, blue for less, grey is neutral")
        return {"FINISHED"}


class TOPSTOC_OT_set_guidance(bpy.types.Operator):
    """Set the guidance of the selected vertices or faces (written to the painted layer)"""

    bl_idname = "topstoc.set_guidance"
    bl_label = "Set Guidance"
    bl_options = {"REGISTER", "UNDO"}

    level: EnumProperty(name="Level", items=LEVELS, default="KEEP")
    value: FloatProperty(name="Value", default=0.0, min=-1.0, max=1.0, description="u for Custom")

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, None if context.mode == "EDIT_MESH" and context.edit_object is not None
                            else "Works in Edit Mode: select vertices or faces first")

    def execute(self, context):
        obj = context.edit_object
        u = self.value if self.level == "CUSTOM" else rules.GUIDANCE_LEVELS[self.level]
        faces = context.tool_settings.mesh_select_mode[2]
        bpy.ops.object.mode_set(mode="OBJECT")
        try:
            mesh = obj.data
            vertex_mask = edge_flags.read_element_flag(mesh, "POINT", "select")
            polygon_mask = edge_flags.read_element_flag(mesh, "FACE", "select") if faces else None
            count = write_guidance(obj, vertex_mask, polygon_mask, u)
        finally:
            bpy.ops.object.mode_set(mode="EDIT")
        self.report({"INFO"}, f"Guidance {u:+.2f} set on {count} {'corners' if faces else 'elements'}")
        return {"FINISHED"}


class TOPSTOC_OT_show_guidance(bpy.types.Operator):
    """Show the painted guidance in the viewport (solid shading coloured by the guidance layer)"""

    bl_idname = "topstoc.show_guidance"
    bl_label = "Show Guidance"

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh(context)
        if reason is None and (context.space_data is None or context.space_data.type != "VIEW_3D"):
            reason = "Run this from a 3D Viewport"
        return polls.refuse(cls, reason)

    def execute(self, context):
        obj = context.object
        attribute = obj.data.color_attributes.get(obj.topstoc.color_attribute)
        if attribute is None:
            self.report({"ERROR"}, f"'{obj.name}' has no guidance layer '{obj.topstoc.color_attribute}'")
            return {"CANCELLED"}
        obj.data.color_attributes.active_color = attribute
        shading = context.space_data.shading
        if shading.type not in {"SOLID"}:
            shading.type = "SOLID"
        shading.color_type = "VERTEX"  # "Attribute": the active colour attribute
        return {"FINISHED"}


class TOPSTOC_OT_add_box(bpy.types.Operator):
    """Add a cube empty whose inside takes the given guidance"""

    bl_idname = "topstoc.add_box"
    bl_label = "Add Guidance Box"
    bl_options = {"REGISTER", "UNDO"}

    weight: FloatProperty(name="Weight", default=1.0, min=-1.0, max=1.0)

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.object_mode(context))

    def execute(self, context):
        box = bpy.data.objects.new("TopStoc Box", None)
        box.empty_display_type = "CUBE"
        box.location = context.scene.cursor.location
        box.topstoc.box_enabled = True
        box.topstoc.box_weight = self.weight
        context.collection.objects.link(box)
        for obj in context.selected_objects:
            obj.select_set(False)
        box.select_set(True)
        context.view_layer.objects.active = box
        return {"FINISHED"}


CLASSES = (TOPSTOC_OT_add_guidance_layer, TOPSTOC_OT_set_guidance, TOPSTOC_OT_show_guidance, TOPSTOC_OT_add_box)
