"""Decimation panels: target and options, guidance sources, preview/multiview/LODs, samples."""
# Shared by every panel of the tab: ui/topology.py and ui/metrics.py use _Panel, _MeshPanel and _mesh.

from __future__ import annotations

import bpy

from ..decimation.pipeline import face_estimate

CATEGORY = "TopStoc"


def wrapped(layout, context, text: str, icon: str = "NONE") -> None:
    """A long message as several labels, broken between words where the sidebar's width ends
    (measured in the UI font; a box's margins allowed for)."""
    scale = (context.preferences.system.ui_scale if context.preferences else 0.0) or 1.0  # 0 in background
    unit = 20 * scale
    pixels = context.region.width if context.region else 300
    # the panel's content (less the tab column and margins), a box's margins, a label's own, its icon
    width = pixels - 2.6 * unit - 0.5 * unit - 0.7 * unit - (unit if icon != "NONE" else 0)
    lines, line = [], ""
    for word in text.split(" "):  # only at spaces: "3\u00a0%" (a no-break space) stays whole
        candidate = f"{line} {word}" if line else word
        if line and _text_width(context, candidate, scale) > width:
            lines.append(line)
            candidate = word
        line = candidate
    col = layout.column(align=True)  # the lines of one message close together
    for i, part in enumerate(lines + [line]):
        col.label(text=part, icon=icon if i == 0 else ("BLANK1" if icon != "NONE" else "NONE"))


def _text_width(context, text: str, scale: float) -> float:
    """Width of ``text`` in pixels in the UI's widget font."""
    import blf

    points = context.preferences.ui_styles[0].widget.points if context.preferences else 11
    try:
        blf.size(0, points * scale)
    except TypeError:  # Blender before 4.0 takes a dpi argument
        blf.size(0, points * scale, 72)
    return blf.dimensions(0, text)[0]


class _Panel:
    """A panel of the TopStoc tab; its id is its class name (Blender's default for bl_idname)."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = CATEGORY


class _ClosedPanel(_Panel):
    """A sub-panel (``bl_parent_id``) that starts closed."""

    bl_options = {"DEFAULT_CLOSED"}


class _SettingsPanel(_Panel):
    """A panel of the scene's decimation settings."""

    def draw(self, context):
        self.draw_settings(context, self.layout, context.scene.topstoc)


class _ClosedSettingsPanel(_SettingsPanel, _ClosedPanel):
    """A closed sub-panel of the scene's decimation settings."""


def property_split(layout):
    """``layout`` with each property's name in a label column beside its field, no decorators."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    return layout


def _mesh(context):
    """The active object if it is a mesh, else None."""
    obj = context.active_object
    return obj if obj is not None and obj.type == "MESH" else None


class _MeshPanel(_Panel):
    """A panel about the active mesh object: asks for one when there is none."""

    def draw(self, context):
        obj = _mesh(context)
        if obj is None:
            self.layout.label(text="Select a mesh")
            return
        self.draw_mesh(context, self.layout, obj)


def _estimate_text(context, settings) -> str:
    obj = context.active_object
    if obj is None or obj.type != "MESH":
        return ""
    estimate = face_estimate(settings, obj.data)
    if estimate is None:
        return "Face Count: when run"
    return f"Face Count ≈ {estimate:,}"


def draw_bake(layout, settings) -> None:
    """The Bake Normals option and, when on, its settings (the panel and the operators' redo panels)."""
    row = layout.row()  # the checkbox's name beside it over the full width: the value column cuts it
    row.use_property_split = False
    row.prop(settings, "bake_normals")
    if settings.bake_normals:
        col = layout.column(align=True)
        col.prop(settings, "bake_size", text="Size")  # "Resolution" does not fit the label column
        col.prop(settings, "bake_margin")
        col.prop(settings, "bake_store")
        col.prop(settings, "bake_colour")


class TOPSTOC_PT_decimate(_SettingsPanel, bpy.types.Panel):
    bl_label = "Guided Decimation"
    bl_order = 0

    def draw_settings(self, context, layout, settings):
        row = layout.row(align=True)
        row.menu("TOPSTOC_MT_presets", text="Presets")
        row.operator("topstoc.preset_add", text="", icon="ADD")
        row.operator("topstoc.preset_add", text="", icon="REMOVE").remove_active = True
        property_split(layout)
        col = layout.column(align=True)
        col.prop(settings, "target_mode")
        if settings.target_mode == "RATIO":
            col.prop(settings, "ratio")
        elif settings.target_mode == "VERTICES":
            col.prop(settings, "vertices")
        elif settings.target_mode == "TRIANGLES":
            col.prop(settings, "triangles")
        else:
            col.prop(settings, "max_error")
            col.prop(settings, "max_error_relative", text="Percent")
        estimate = _estimate_text(context, settings)
        if estimate:
            layout.label(text=estimate, icon="MESH_DATA")
        layout.prop(settings, "quality")
        row = layout.row()  # no label column: "Symmetry" does not fit it in every Blender's font
        row.use_property_split = False
        row.prop(settings, "use_symmetry")
        sub = row.row()
        sub.active = settings.use_symmetry
        sub.prop(settings, "symmetry_axis", text="")
        row = layout.row(align=True)  # full width: "New Object" does not fit beside a label
        row.use_property_split = False
        row.prop(settings, "output", expand=True)
        draw_bake(layout, settings)
        col = layout.column(align=True)
        col.operator("topstoc.guided_decimate", icon="MOD_DECIM")
        col.operator("topstoc.preview", icon="HIDE_OFF")
        obj = context.active_object
        missed = obj.get("topstoc_target_missed", "") if obj is not None else ""
        if not missed and obj is not None and obj.get("topstoc_over_budget", 0):  # results of older versions
            missed = f"{obj['topstoc_over_budget']:,} vertices over the target: {obj.get('topstoc_over_budget_reason', '')}"
        if missed:
            wrapped(layout, context, missed, "ERROR")
        if obj is not None and obj.type == "MESH" and obj.topstoc.settings:
            box = layout.box()
            source = obj.topstoc.source
            wrapped(box, context, f"Result of {source.name}" if source else "Source deleted", "LINKED")
            col = box.column()  # one per line: side by side, a row's equal halves cut "Regenerate"
            col.use_property_split = False  # the checkbox's name beside it, not in a label column
            col.operator("topstoc.regenerate", icon="FILE_REFRESH")
            col.prop(obj.topstoc, "auto_regenerate")


class TOPSTOC_PT_advanced(_ClosedSettingsPanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_parent_id = "TOPSTOC_PT_decimate"

    def draw_settings(self, context, layout, settings):
        property_split(layout)
        col = layout.column(align=True)
        col.prop(settings, "seed")
        col.prop(settings, "adaptivity")
        layout.prop(settings, "density")
        row = layout.row()
        row.active = settings.quality != "FAST"  # only the refinement weighs UVs, colours and normals
        row.use_property_split = False  # the name inside a full-width slider: it fits the sidebar
        row.prop(settings, "attribute_weight", slider=True)
        col = layout.column(align=True)
        col.active = settings.quality == "CUSTOM"
        col.prop(settings, "placement")
        col.prop(settings, "refine")
        if settings.quality != "CUSTOM":
            layout.label(text="Set by Quality", icon="INFO")


class TOPSTOC_PT_guidance(_Panel, bpy.types.Panel):
    bl_label = "Guidance"
    bl_parent_id = "TOPSTOC_PT_decimate"

    def draw(self, context):
        layout = self.layout
        obj = context.object
        scene = context.scene.topstoc
        if obj is not None and obj.type == "EMPTY":
            layout.prop(obj.topstoc, "box_enabled")
            if obj.empty_display_type != "CUBE":
                layout.label(text="Only cube empties act as boxes", icon="INFO")
            layout.prop(obj.topstoc, "box_weight")
            return
        if obj is None or obj.type != "MESH":
            layout.label(text="Select a mesh")
            return
        s = obj.topstoc
        box = layout.box()
        box.prop(s, "use_color")
        if s.use_color:
            if obj.data.color_attributes.get(s.color_attribute) is not None:
                box.prop_search(s, "color_attribute", obj.data, "color_attributes", text="Layer")
            else:  # no red "invalid" field before the layer exists: offer to make it
                box.label(text="Not painted yet", icon="INFO")
            box.prop(s, "color_strength")
            col = box.column(align=True)  # side by side, each icon and name has half the width: too little
            col.operator("topstoc.add_guidance_layer", text="Add Layer", icon="BRUSH_DATA")
            col.operator("topstoc.show_guidance", text="Show", icon="SHADING_SOLID")
        if context.mode == "EDIT_MESH":  # two rows: five buttons in one are cut
            for levels in ((("KEEP", "Keep"), ("MORE", "More"), ("NEUTRAL", "Neutral")),
                           (("LESS", "Less"), ("DROP", "Drop"))):
                row = box.row(align=True)
                for level, label in levels:
                    row.operator("topstoc.set_guidance", text=label).level = level
        box = layout.box()
        box.prop(s, "use_vertex_group")
        if s.use_vertex_group:  # a label column: beside its field a name gets a third and is cut
            col = property_split(box.column())
            col.prop_search(s, "vertex_group", obj, "vertex_groups")
            col.prop(s, "vertex_group_mapping")
            col.prop(s, "vertex_group_strength")
        box = layout.box()
        box.prop(s, "use_materials")
        if s.use_materials and obj.material_slots:
            col = box.column(align=True)
            for index, slot in enumerate(obj.material_slots[:len(s.material_weights)]):
                col.prop(s, "material_weights", index=index, text=slot.name or f"Slot {index}")
            box.prop(s, "material_strength")
        layout.prop(s, "use_uv_seams")
        layout.prop(s, "use_sharp")
        layout.prop(s, "use_hard_normals")
        box = layout.box()
        box.prop(scene, "use_boxes")
        if scene.use_boxes:
            box.prop(scene, "box_strength")
            box.operator("topstoc.add_box", icon="CUBE")
        box = layout.box()
        box.prop(scene, "use_view")
        if scene.use_view:
            col = property_split(box.column())  # as the vertex group's settings
            col.prop(scene, "view_source")
            box.prop(scene, "back_ratio")
            box.prop(scene, "silhouette_angle")
            box.prop(scene, "silhouette_falloff")
            box.prop(scene, "use_frustum")
            if scene.use_frustum:
                box.prop(scene, "outside_probability")


class TOPSTOC_PT_variants(_ClosedSettingsPanel, bpy.types.Panel):
    bl_label = "Multiview & LODs"
    bl_parent_id = "TOPSTOC_PT_decimate"

    def draw_settings(self, context, layout, settings):
        col = layout.column(align=True)
        col.prop(settings, "variants")
        col.prop(settings, "variance")
        layout.operator("topstoc.multiview", icon="MOD_ARRAY")
        layout.label(text="LOD ratios, finest first:")
        layout.prop(settings, "lod_ratios", text="")
        layout.operator("topstoc.lod_chain", icon="MOD_DECIM")


class TOPSTOC_PT_samples(_MeshPanel, _ClosedPanel, bpy.types.Panel):
    bl_label = "Samples"
    bl_parent_id = "TOPSTOC_PT_decimate"

    def draw_mesh(self, context, layout, obj):
        show = context.scene.topstoc.overlays
        col = layout.column(align=True)  # the last decimation's samples and clusters (thesis fig. 4.1)
        col.prop(show, "show_samples", toggle=True, icon="DOT")
        col.prop(show, "show_clusters", toggle=True, icon="MOD_EXPLODE")
        layout.operator("topstoc.save_samples", icon="FILE_TICK")
        for entry in obj.topstoc.sample_sets:
            row = layout.row(align=True)
            row.label(text=f"{entry.name}: {entry.vertices_out:,} vertices")
            row.operator("topstoc.restore_samples", text="", icon="RECOVER_LAST").name = entry.name
            row.operator("topstoc.remove_samples", text="", icon="X").name = entry.name


CLASSES = (TOPSTOC_PT_decimate, TOPSTOC_PT_advanced, TOPSTOC_PT_guidance, TOPSTOC_PT_variants, TOPSTOC_PT_samples)
