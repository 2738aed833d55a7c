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


def close_up(obj, ids):
    """Points the view at the loop's vertices from above the surface there (their mean normal,
    tilted 35 degrees), 14 loop radii away, with the wireframe on: the arch and the triangles
    around it fill the view. Returns the view (location, rotation, distance) to come back to."""
    from mathutils import Quaternion

    _window, _area, _region, space = session.view3d()
    world = obj.matrix_world
    points = [world @ obj.data.vertices[i].co for i in ids]
    centre = sum(points, Vector()) / len(points)
    radius = max((p - centre).length for p in points)
    normal = (world.to_3x3() @ sum((obj.data.vertices[i].normal for i in ids), Vector())).normalized()
    view = space.region_3d
    view.view_location = centre
    view.view_rotation = normal.to_track_quat("Z", "Y") @ Quaternion((1, 0, 0), 0.6)
    view.view_distance = 14 * radius
    space.overlay.show_wireframes = True
    return view.view_location.copy(), view.view_rotation.copy(), view.view_distance


def keep_middle(shot_name, file_name, width=560, height=420):
    """With TOPSTOC_DOC_SHOTS=DIR, saves the middle of the 3D view of a screenshot (a small file)."""
    folder = os.environ.get("TOPSTOC_DOC_SHOTS")
    if not folder:
        return
    _window, _area, region, _space = session.view3d()
    pixels = np.load(os.path.join(session.OUT, shot_name + ".npy"))
    x0 = region.x + (region.width - width) // 2
    y0 = region.y + (region.height - height) // 2
    crop = np.ascontiguousarray(pixels[y0:y0 + height, x0:x0 + width])
    image = bpy.data.images.new(file_name, width, height, alpha=False)
    image.pixels.foreach_set(crop.ravel())
    image.filepath_raw, image.file_format = os.path.join(os.path.abspath(folder), file_name), "PNG"
    image.save()
    bpy.data.images.remove(image)


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

    view = space.region_3d
    full = (view.view_location.copy(), view.view_rotation.copy(), view.view_distance)
    close = close_up(obj, ids)
    yield 0.5
    session.shot("close_before", [obj])
    keep_middle("close_before", "clean-close-before.png")
    view.view_location, view.view_rotation, view.view_distance = full
    space.overlay.show_wireframes = False

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
    press(window, "NUMPAD_MINUS")  # both sizes down by 1.5: fewer handles to remove
    yield 0.5
    values["smaller_preview_handles"] = clean_plan.shown(obj).handles
    press(window, "NUMPAD_PLUS")   # and back
    yield 0.5
    plan = clean_plan.shown(obj)
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
    view.view_location, view.view_rotation, view.view_distance = close  # the same close view as before
    space.overlay.show_wireframes = True
    yield 0.5
    session.shot("close_after", [obj])
    keep_middle("close_after", "clean-close-after.png")
    view.view_location, view.view_rotation, view.view_distance = full
    space.overlay.show_wireframes = False

    with session.override():
        bpy.ops.ed.undo()
    yield 0.5
    obj = bpy.data.objects["Scan"]
    values["genus_undone"], values["vertices_undone"] = obj.topstoc.topology.genus, len(obj.data.vertices)
    values["holes_undone"] = obj.topstoc.topology.boundary_loops


session.run(steps)
