"""Run by test_labels_gui.py in a windowed Blender under Xvfb: every TopStoc panel open at the
default sidebar width, in Object and in Edit Mode; each panel's layout (UILayout.introspect, as
Blender resolved it) measured by label_widths.py; the texts that would be cut go to the report.
Screenshot: the sidebar with every panel open (a tall window shows them all)."""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import label_widths  # noqa: E402
import session  # noqa: E402
from session import report, shot, view3d  # noqa: E402

ADDON = session.enable_addon()


def open_every_panel():
    """Registers our panels again, none closed by default (Blender 3.4 has no API to open one)."""
    names = [name for name in dir(bpy.types) if name.startswith("TOPSTOC_PT_")]
    classes = sorted((getattr(bpy.types, name) for name in names),
                     key=lambda c: (bool(getattr(c, "bl_parent_id", "")), getattr(c, "bl_order", 0)))
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
    for cls in classes:
        cls.bl_options = set()
        bpy.utils.register_class(cls)
    return classes


class Recording:
    """A panel as its draw() sees it, with its layout an IconRecorder."""

    def __init__(self, panel):
        self._panel = panel
        self.layout = label_widths.IconRecorder(panel.layout)

    def __getattr__(self, name):
        return getattr(self._panel, name)


def capture_layouts(classes):
    """Steps: draws the sidebar once with every panel's draw() wrapped to keep its introspected layout."""
    layouts = {}

    def wrapped(cls, draw):
        def draw_and_keep(self, context):
            draw(Recording(self), context)
            layouts[cls.__name__] = label_widths.parse(self.layout.introspect())
        return draw_and_keep

    def wrapped_item(draw):
        def draw_item(self, context, layout, *args):
            return draw(self, context, label_widths.IconRecorder(layout), *args)
        return draw_item

    lists = [getattr(bpy.types, name) for name in dir(bpy.types) if name.startswith("TOPSTOC_UL_")]
    originals = {cls: cls.draw for cls in classes}
    list_originals = {cls: cls.draw_item for cls in lists}
    for cls in classes:
        cls.draw = wrapped(cls, originals[cls])
    for cls in lists:
        cls.draw_item = wrapped_item(list_originals[cls])
    try:
        _window, area, _region, _space = view3d()
        area.tag_redraw()
        yield 0.5
    finally:
        for cls, draw in originals.items():
            cls.draw = draw
        for cls, draw in list_originals.items():
            cls.draw_item = draw
    report["values"].setdefault("layouts", []).append(layouts)


def measure(mode: str):
    """Cut texts of the last captured layouts at the sidebar's width."""
    _window, area, _region, _space = view3d()
    sidebar = next(r for r in area.regions if r.type == "UI")
    # the panels' content: the region less the tab column (one unit) and the panel's margins
    width = sidebar.width - 2.6 * label_widths.unit()
    report["values"]["sidebar_width"] = sidebar.width
    report["values"]["content_width"] = width
    cut = []
    for name, roots in report["values"]["layouts"][-1].items():
        for root in roots:
            for text, needs, has, path in label_widths.cut_texts(root, width):
                cut.append([mode, name, text, needs, has, path])
    report["values"].setdefault("cut", []).extend(cut)
    report["values"].setdefault("texts", {})[mode] = sum(
        _count_texts(root) for roots in report["values"]["layouts"][-1].values() for root in roots)


def _count_texts(item) -> int:
    if "items" in item:
        return sum(_count_texts(child) for child in item["items"])
    return 1 if item.get("draw_string") else 0


def steps():
    result = bpy.data.objects["Shape_TopStoc"]
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    result.select_set(True)
    bpy.context.view_layer.objects.active = result
    with session.override():  # the topology panels' tables and loop list filled in
        assert bpy.ops.topstoc.analyse() == {"FINISHED"}
        assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    classes = open_every_panel()
    session.frame([result], tilt=0.2, turn=0.0, distance_factor=2.2)
    yield from session.show_topstoc_tab()
    yield 0.5
    yield from capture_layouts(classes)
    measure("object")
    shot("panels_object", [result])
    # every option that shows more settings, on
    settings = bpy.context.scene.topstoc
    for name in ("bake_normals", "use_view", "use_frustum", "use_symmetry"):
        if hasattr(settings, name):
            setattr(settings, name, True)
    result.topstoc.use_vertex_group = True
    bpy.context.scene.topstoc.overlays.show_error = True
    yield from capture_layouts(classes)
    measure("options")
    shot("panels_options", [result])
    with session.override():
        bpy.ops.object.mode_set(mode="EDIT")
    yield 0.5
    yield from capture_layouts(classes)
    measure("edit")
    shot("panels_edit", [result])
    with session.override():
        bpy.ops.object.mode_set(mode="OBJECT")
    report["values"].pop("layouts")
    yield from frame_the_shortest_loop(result)


def loop_extent(obj, ids):
    """Pixels the loop spans in the 3D view (the larger of its screen width and height)."""
    from bpy_extras import view3d_utils
    from mathutils import Vector

    _window, _area, region, space = view3d()
    points = [view3d_utils.location_3d_to_region_2d(region, space.region_3d, obj.matrix_world @ Vector(
        obj.data.vertices[i].co)) for i in ids]
    xs, ys = [p.x for p in points if p], [p.y for p in points if p]
    return max(max(xs) - min(xs), max(ys) - min(ys)) if xs else 0.0


def frame_the_shortest_loop(obj):
    """Steps: Frame Loop on the shortest handle or tunnel loop makes it fill the view."""
    topology = obj.topstoc.topology
    loops = [i for i, loop in enumerate(topology.loops) if loop.kind in ("HANDLE", "TUNNEL")]
    topology.loop_index = min(loops, key=lambda i: topology.loops[i].length)
    ids = [int(i) for i in topology.loops[topology.loop_index]["vertices"]]
    session.frame([obj], tilt=0.2, turn=0.0, distance_factor=20.0)  # zoomed out: the whole object small
    yield 0.3
    before = loop_extent(obj, ids)
    with session.override():
        done = bpy.ops.topstoc.frame_loop()
    yield 0.5
    after = loop_extent(obj, ids)
    _window, _area, region, _space = view3d()
    report["values"]["loop_extent"] = [len(ids), before, after, min(region.width, region.height)]
    session.check("Frame Loop fills the view with the loop", done == {"FINISHED"} and before < 0.1 * after
                  and after > 0.25 * min(region.width, region.height), f"{before:.0f} px -> {after:.0f} px")
    shot("framed_loop", [obj])


session.run(steps)
