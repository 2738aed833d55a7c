"""GUI script (see test_topology_gui.py): loop, generator and boundary overlays on a saved,
analysed genus-g scene; the active loop thicker; depth test against an occluder; toggles;
editing from the panel's operators; the background search with progress and Esc; overlays
gone after the add-on is disabled."""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import session  # noqa: E402

KINDS = ("show_handles", "show_tunnels", "show_generators", "show_boundary", "show_nonmanifold")


def only(show, *names):
    for name in KINDS + ("show_samples", "show_clusters", "show_error"):
        setattr(show, name, name in names)


def occluder(obj, space):
    """A plane between the viewer and the left half of ``obj``."""
    from mathutils import Vector

    view = space.region_3d
    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    center = sum(corners, Vector()) / 8
    radius = max((c - center).length for c in corners)
    rotation = view.view_rotation
    toward_viewer = rotation @ Vector((0, 0, 1))
    left = rotation @ Vector((-1, 0, 0))
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    plane = bpy.context.active_object
    plane.name = "Occluder"
    plane.rotation_mode = "QUATERNION"
    plane.rotation_quaternion = rotation
    plane.location = center + toward_viewer * radius * 1.2 + left * radius * 0.75
    plane.scale = (radius * 1.2, radius * 3.0, 1.0)
    return plane


def steps():
    session.enable_addon()
    scene = bpy.context.scene
    show = scene.topstoc.overlays
    obj = bpy.data.objects["Shape"]
    bpy.context.view_layer.objects.active = obj
    obj.select_set(False)
    window, area, region, space = session.view3d()
    yield from session.show_topstoc_tab("TOPSTOC_PT_topology")
    yield from session.collapse_first_panel()
    session.frame([obj])
    topology = obj.topstoc.topology
    session.report["values"]["genus"] = topology.genus
    session.report["values"]["loops"] = [loop.kind for loop in topology.loops]
    show.line_width, show.active_width, show.point_size = 3.0, 9.0, 7.0
    show.marker_size = 0.0  # no rings round small loops: they are drawn over everything (test_clean_gui.py)

    # 1. Each overlay alone, then all off.
    only(show)
    yield 0.4
    session.shot("topology_off", [obj])
    kinds = [loop.kind for loop in topology.loops]
    topology.loop_index = kinds.index("TUNNEL")  # the active loop is not a handle: handles all thin
    only(show, "show_handles")
    yield 0.4
    session.shot("handles_thin", [obj])
    topology.loop_index = kinds.index("HANDLE")
    yield 0.4
    session.shot("handles_active", [obj])
    only(show, "show_tunnels")
    yield 0.4
    session.shot("tunnels", [obj])
    only(show, "show_generators")
    yield 0.4
    session.shot("generators", [obj])
    only(show, *KINDS)
    yield 0.4
    session.shot("topology_all", [obj])
    session.keep_for_docs("topology_all", "topology-overlays.png")

    # 2. Depth test: a plane in front of the left half hides the overlays there.
    plane = occluder(obj, space)
    bpy.context.view_layer.objects.active = obj
    plane.select_set(False)
    yield 0.4
    session.shot("occluded", [obj, plane])
    bpy.data.objects.remove(plane)

    # 3. Editing from the panel: cut along the active handle -> red boundary vertices appear.
    with session.override():
        result = bpy.ops.topstoc.cut_loop("EXEC_DEFAULT", True)
    session.check("cut along the active loop", result == {"FINISHED"} and topology.boundary_loops == 2)
    session.report["values"]["genus_after_cut"] = topology.genus
    only(show, "show_boundary")
    yield 0.4
    session.shot("boundary", [obj])
    with session.override():
        bpy.ops.ed.undo()
    obj = bpy.data.objects["Shape"]
    topology = obj.topstoc.topology
    session.check("undo restores the genus", topology.genus == session.report["values"]["genus"]
                  and topology.boundary_loops == 0)

    # 4. The background search: progress, Esc cancels, a second run finishes.
    only(show, "show_handles", "show_tunnels")
    bpy.context.view_layer.objects.active = obj
    with session.override():
        result = bpy.ops.topstoc.find_loops("INVOKE_DEFAULT")
    session.check("search runs in the background", result == {"RUNNING_MODAL"})
    from topstoc.blender.operators.topology import running

    session.check("search listed as running", obj.name in running)
    window.event_simulate(type="ESC", value="PRESS")
    window.event_simulate(type="ESC", value="RELEASE")
    for _ in range(100):
        yield 0.2
        if obj.name not in running:
            break
    session.report["values"]["cancel_state"] = (topology.loops_state, topology.loops_message)
    session.check("Esc cancels the search", obj.name not in running and topology.loops_message == "Search cancelled")
    with session.override():
        bpy.ops.topstoc.find_loops("INVOKE_DEFAULT")
    for _ in range(300):
        yield 0.2
        if obj.name not in running:
            break
    session.check("a second search finishes", topology.loops_state == "OK"
                  and sum(loop.kind == "HANDLE" for loop in topology.loops) == topology.genus)
    session.report["values"]["search_message"] = topology.loops_message
    yield 0.4
    session.shot("after_search", [obj])

    # 5. Disabling the add-on removes the draw handlers: nothing is drawn any more.
    import addon_utils

    from topstoc.blender.ui import overlays

    addon_utils.disable("topstoc", default_set=True)
    session.check("draw handlers removed", overlays._handlers == {})
    yield 0.5
    session.shot("disabled", [obj])


session.run(steps)
