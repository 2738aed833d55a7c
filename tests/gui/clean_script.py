"""GUI script (see test_clean_gui.py): the clean-up on a scan with pinched handles, as an artist
runs it: the loops found and ringed at the zoom that shows the whole scan, Frame Loop on the
smallest, the clean-up's preview (Enter applies, Esc cancels), the result, and undo."""

import os
import sys

import bpy
import numpy as np
from bpy_extras import view3d_utils
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import session  # noqa: E402

SHOWN = ("show_handles", "show_tunnels")


def press(window, key):
    window.event_simulate(type=key, value="PRESS")
    window.event_simulate(type=key, value="RELEASE")


def loop_on_screen(obj, ids):
    """Window pixels of the loop's vertices (None for those behind the eye)."""
    _window, _area, region, space = session.view3d()
    co = obj.data.vertices
    points = [view3d_utils.location_3d_to_region_2d(region, space.region_3d, obj.matrix_world @ co[i].co)
              for i in ids]
    return [None if p is None else (region.x + p.x, region.y + p.y) for p in points]


def steps():
    session.enable_addon()
    from topstoc.blender.analysis import clean_plan

    show = bpy.context.scene.topstoc.overlays
    for name in ("show_handles", "show_tunnels", "show_generators", "show_boundary", "show_nonmanifold"):
        setattr(show, name, name in SHOWN)
    obj = bpy.data.objects["Scan"]
    bpy.context.view_layer.objects.active = obj
    obj.select_set(False)
    window, area, region, space = session.view3d()
    yield from session.show_topstoc_tab("TOPSTOC_PT_topology")
    yield from session.collapse_first_panel()
    session.frame([obj], tilt=0.1, turn=0.0, distance_factor=2.0)
    topology = obj.topstoc.topology
    values = session.report["values"]
    values["genus_before"], values["vertices_before"] = topology.genus, len(obj.data.vertices)
    values["holes_before"] = topology.boundary_loops
    values["loop_sizes"] = [loop.relative for loop in topology.loops]
    yield 0.5
    session.shot("clean_before", [obj])
    session.keep_for_docs("clean_before", "clean-before.png")

    # Frame Loop on the smallest loop: it fills a good part of the view afterwards.
    topology.loop_index = 0
    ids = [int(i) for i in topology.loops[0]["vertices"]]
    before = loop_on_screen(obj, ids)
    with session.override():
        result = bpy.ops.topstoc.frame_loop()
    yield 0.5
    after = loop_on_screen(obj, ids)
    view = session.view_rect()
    values["loop_pixels_before"] = [list(p) for p in before if p is not None]
    values["loop_pixels_after"] = [list(p) for p in after if p is not None]
    values["view_rect"] = view
    session.check("frame loop ran", result == {"FINISHED"})
    session.shot("frame_loop", [obj])
    session.frame([obj], tilt=0.1, turn=0.0, distance_factor=2.0)

    # The clean-up from the panel's button: a preview first, Esc leaves the mesh as it was.
    with session.override():
        result = bpy.ops.topstoc.clean("INVOKE_DEFAULT", max_handle=1.0, max_hole=1.0)
    session.check("clean-up waits for a decision", result == {"RUNNING_MODAL"})
    yield 0.5
    press(window, "ESC")
    yield 0.5
    session.check("Esc cancels: no preview, mesh unchanged",
                  clean_plan.shown(obj) is None and len(obj.data.vertices) == values["vertices_before"]
                  and topology.genus == values["genus_before"])

    with session.override():
        result = bpy.ops.topstoc.clean("INVOKE_DEFAULT", max_handle=1.0, max_hole=1.0)
    yield 0.5
    plan = clean_plan.shown(obj)
    session.check("the preview is shown", result == {"RUNNING_MODAL"} and plan is not None)
    values["preview"] = {"handles": plan.handles, "holes": plan.holes, "left": plan.left,
                         "summary": plan.summary()}
    session.shot("clean_preview", [obj])
    session.keep_for_docs("clean_preview", "clean-preview.png")
    press(window, "RET")
    yield 1.0
    obj = bpy.data.objects["Scan"]
    topology = obj.topstoc.topology
    values["genus_after"], values["vertices_after"] = topology.genus, len(obj.data.vertices)
    values["holes_after"] = topology.boundary_loops
    values["edit_message"] = topology.edit_message
    session.check("Enter applied the clean-up", clean_plan.shown(obj) is None
                  and values["vertices_after"] > values["vertices_before"])
    yield 0.3
    session.shot("clean_after", [obj])
    session.keep_for_docs("clean_after", "clean-after.png")

    with session.override():
        bpy.ops.ed.undo()
    yield 0.5
    obj = bpy.data.objects["Scan"]
    values["genus_undone"], values["vertices_undone"] = obj.topstoc.topology.genus, len(obj.data.vertices)
    values["holes_undone"] = obj.topstoc.topology.boundary_loops


session.run(steps)
