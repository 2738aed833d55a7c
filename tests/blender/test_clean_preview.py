"""The clean-up's preview and the small-loop tools in Blender: the preview's counts and overlay
against what the clean-up then does (and an independent clean of the same arrays), undo giving
the mesh back, rings around loops too small to see, and Frame Loop bringing a tiny loop into view."""

import importlib
import math

import bpy
import numpy as np
import pytest
from mathutils import Vector

import cleanup_meshes
from helpers import make_object, positions, snapshot


@pytest.fixture
def mods(ts):
    names = {"plan": "blender.analysis.clean_plan", "overlay_data": "blender.ui.overlay_data",
             "colors": "core.support.colors", "clean": "core.api.clean", "mesh_read": "blender.io.mesh_read"}
    return type("Mods", (), {key: importlib.import_module(f"{ts.__name__}.{name}") for key, name in names.items()})


def arches_with_holes():
    """A block with 4 unit arches (loops 4) and 1 large one (loops 12), beside a plate with 2
    small holes (border 4) and 1 large (border 16) and its edge: small flaws and large ones."""
    block, block_triangles = cleanup_meshes.block_with_arches(4, 1, jitter=0.05, seed=11)
    plate, plate_triangles = cleanup_meshes.perforated_plate(2, 1, side=14, jitter=0.05, seed=3)
    vertices = np.vstack([block, plate + [0.0, 0.0, -4.0]])
    return vertices, np.vstack([block_triangles, plate_triangles + len(block)])


def percent(vertices, length):
    return 100 * length / np.linalg.norm(np.ptp(vertices, axis=0))


def test_preview_counts_are_what_the_clean_up_does_and_undo_restores(mods, scene):
    vertices, triangles = arches_with_holes()
    obj = make_object("Flaws", vertices, triangles)
    name = obj.name
    size = percent(vertices, 6.0)
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    t = obj.topstoc.topology
    genus, holes = t.genus, t.boundary_loops
    assert (genus, holes) == (5, 4)
    before = snapshot(obj.data)

    arrays = mods.mesh_read.read_mesh(obj.data)
    plan = mods.plan.plan(obj, arrays, f"{size}%", f"{size}%", None)
    mods.plan.show(obj, plan)
    assert snapshot(obj.data) == before                          # previewing changes nothing
    assert (plan.handles, plan.holes) == (4, 2)
    # the same counts from a clean-up of the same arrays made here, without the plan's memo
    alone = mods.clean.clean(arrays.vertices, arrays.triangles, max_handle=f"{size}%", max_hole=f"{size}%")
    assert (alone.count("handle") + alone.count("tunnel"), alone.count("hole"), len(alone.left)) == \
        (plan.handles, plan.holes, plan.left)
    assert plan.summary() == f"removes 4 handles, fills 2 holes; leaves {plan.left}"

    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    bpy.ops.ed.undo_push(message="before the clean-up")
    assert bpy.ops.topstoc.clean("EXEC_DEFAULT", True, max_handle=size, max_hole=size) == {"FINISHED"}
    obj = bpy.data.objects[name]
    t = obj.topstoc.topology
    assert genus - t.genus == plan.handles and holes - t.boundary_loops == plan.holes  # done = shown
    assert t.edit_message.startswith("Removes 4 handles, fills 2 holes")
    assert mods.plan.shown(obj) is None                          # the preview ends with the clean-up
    # a cut loop's edges stay (a cap's rim): no searched loop is kept, Find Loops lists what is left
    assert [loop.kind for loop in t.loops] == ["BOUNDARY"] * t.boundary_loops and "Find Loops" in t.loops_message
    bpy.ops.ed.undo()
    obj = bpy.data.objects[name]
    assert snapshot(obj.data) == before
    assert (obj.topstoc.topology.genus, obj.topstoc.topology.boundary_loops) == (5, 4)


def test_preview_overlay_draws_removed_green_and_left_violet(mods, scene):
    vertices, triangles = arches_with_holes()
    obj = make_object("Flaws", vertices, triangles)
    size = percent(vertices, 6.0)
    plan = mods.plan.plan(obj, mods.mesh_read.read_mesh(obj.data), f"{size}%", f"{size}%", None)
    assert mods.overlay_data.clean_preview_primitives(obj) == []  # made, not shown
    mods.plan.show(obj, plan)
    prims = {p.name: p for p in mods.overlay_data.clean_preview_primitives(obj)}
    co = positions(obj.data).astype(np.float64)
    removed = prims["clean_remove"].positions.reshape(-1, 2, 3).astype(np.float64)
    left = prims["clean_leave"].positions.reshape(-1, 2, 3).astype(np.float64)
    assert prims["clean_remove"].color == mods.colors.CLEAN_REMOVE and prims["clean_remove"].size == "active"
    assert prims["clean_leave"].color == mods.colors.CLEAN_LEAVE
    # every removed edge is short (a unit arch's loop or a 1-quad hole), every left one belongs to a
    # large loop: the large arch (12), the large hole (16) or the plate's edge (56)
    assert np.linalg.norm(removed[:, 0] - removed[:, 1], axis=1).max() < 1.3
    assert len(removed) == sum(len(ids) for _kind, ids in plan.loops(True))
    lengths = [np.linalg.norm(co[ids] - co[np.roll(ids, -1)], axis=1).sum() for _kind, ids in plan.loops(False)]
    assert min(lengths) > 6.0 and len(left) == sum(len(ids) for _kind, ids in plan.loops(False))
    from test_registration import fake_panel

    panel = importlib.import_module(f"{mods.plan.__name__.rsplit('.', 2)[0]}.ui.topology").TOPSTOC_PT_topology_edit
    seen = set()
    panel.draw(fake_panel(panel, seen), bpy.context)              # the Edit panel draws the preview's box
    assert "topstoc.clean" in seen
    bpy.ops.mesh.primitive_cube_add()
    obj.data = bpy.context.active_object.data                    # another mesh: the preview is stale
    assert mods.overlay_data.clean_preview_primitives(obj) == []
    mods.plan.hide(obj)


def test_rings_mark_only_loops_too_small_on_screen(mods):
    """A loop 0.02 wide seen from 10 away in a 1000-pixel view is about 2 pixels: it gets a ring;
    one 4 wide (about 400 pixels) does not; one behind the eye gets none."""
    width = height = 1000.0
    focal = 1.0 / math.tan(math.radians(45) / 2)
    near, far = 0.1, 100.0
    projection = np.array([[focal, 0, 0, 0], [0, focal, 0, 0],
                           [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])
    view = np.eye(4)
    view[2, 3] = -10.0                                           # the eye at z = 10, looking down -z
    angles = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    ring = np.c_[np.cos(angles), np.sin(angles), np.zeros(6)]
    tiny, big, behind = (0.01 * ring + [1.0, 0.5, 0.0], "tiny"), (2.0 * ring, "big"), (0.01 * ring + [0, 0, 20], "b")
    rings = mods.overlay_data.small_loop_rings([tiny, big, behind], projection @ view, width, height, 28.0)
    assert [colour for *_xy, colour in rings] == ["tiny"]
    x, y, radius, _ = rings[0]
    # independent: the centre's screen position by similar triangles
    assert x == pytest.approx(500 + 500 * focal * 1.0 / 10, abs=0.5) and y == pytest.approx(500 + 500 * focal * 0.5 / 10, abs=0.5)
    assert radius == 14.0
    assert mods.overlay_data.small_loop_rings([tiny], projection @ view, width, height, 0.0) == []


def test_marked_loops_are_the_active_loop_and_the_preview(mods, scene):
    vertices, triangles = arches_with_holes()
    obj = make_object("Flaws", vertices, triangles)
    show = bpy.context.scene.topstoc.overlays
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    t.loop_index = 0
    marked = mods.overlay_data.marked_loops(obj, show)
    searched = [loop for loop in t.loops if loop.kind != "BOUNDARY"]
    assert len(marked) == len(searched) + (t.loops[0].kind == "BOUNDARY")  # every handle and tunnel, the active hole
    for (points, colour), loop in zip(marked, searched):
        np.testing.assert_array_equal(points, positions(obj.data)[np.asarray(loop["vertices"])])
        assert colour == (mods.colors.HANDLE if loop.kind == "HANDLE" else mods.colors.TUNNEL)
    show.show_handles = False
    assert len(mods.overlay_data.marked_loops(obj, show)) == len(searched) // 2 + (t.loops[0].kind == "BOUNDARY")
    show.show_handles = True
    size = percent(vertices, 6.0)
    plan = mods.plan.plan(obj, mods.mesh_read.read_mesh(obj.data), f"{size}%", f"{size}%", None)
    mods.plan.show(obj, plan)
    marked = mods.overlay_data.marked_loops(obj, show)
    assert len(marked) == len(plan.loops(True)) + len(plan.loops(False))  # the preview's rings only
    assert sum(colour == mods.colors.CLEAN_REMOVE for _p, colour in marked) == plan.handles + plan.holes
    mods.plan.hide(obj)


def view3d():
    screen = bpy.context.screen or bpy.data.screens["Layout"]
    area = next(a for a in screen.areas if a.type == "VIEW_3D")
    return screen, area, next(r for r in area.regions if r.type == "WINDOW")


def angular_extent(view, lens, points):
    """Largest angle (radians) of ``points`` off the view's axis, computed from the view's
    location, rotation and distance (Blender's perspective view: the eye is ``distance`` behind
    the location along the view's z), and the angle the view's half height spans at ``lens``
    millimetres (Blender's viewport sensor: 36 mm across the smaller side, at most)."""
    rotation = view.view_rotation.to_matrix()
    eye = view.view_location + rotation @ Vector((0.0, 0.0, view.view_distance))
    angles = []
    for p in points:
        local = rotation.transposed() @ (Vector(p) - eye)
        assert local.z < 0, "a point behind the eye"
        angles.append(math.atan(math.hypot(local.x, local.y) / -local.z))
    return max(angles), math.atan(18.0 / lens)


def test_frame_loop_brings_a_small_loop_into_view(mods, scene):
    vertices, triangles = cleanup_meshes.block_with_arches(9, 0, jitter=0.05, seed=2)
    obj = make_object("Arches", vertices, triangles)
    obj.location = (30.0, -5.0, 2.0)                             # framing works in world space
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    t.loop_index = 4
    ids = np.asarray(t.loops[4]["vertices"])
    points = [obj.matrix_world @ Vector(p) for p in positions(obj.data)[ids].astype(np.float64)]
    screen, area, region = view3d()
    space = area.spaces.active
    view = space.region_3d
    view.view_perspective = "PERSP"
    with bpy.context.temp_override(screen=screen, area=area, region=region):
        assert bpy.ops.topstoc.frame_loop() == {"FINISHED"}
    extent, half_view = angular_extent(view, space.lens, points)
    centre = sum(points, Vector()) / len(points)
    assert (view.view_location - centre).length < 1e-4
    assert 0.1 * half_view < extent < half_view                 # inside the view, and large in it
