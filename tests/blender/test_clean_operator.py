"""The clean-up operator in Blender: small handles and holes go, the large ones stay, the mesh's
untouched faces keep their positions, undo brings everything back."""

import bpy
import numpy as np

import cleanup_meshes
import reference
from helpers import make_object


def genus_and_holes(obj):
    t = obj.topstoc.topology
    return t.genus, t.boundary_loops


def test_clean_removes_small_handles_keeps_large_and_undoes(ts, scene):
    vertices, triangles = cleanup_meshes.block_with_arches(4, 1, jitter=0.05, seed=11)
    obj = make_object("Arches", vertices, triangles)
    name = obj.name
    diagonal = np.linalg.norm(np.ptp(vertices, axis=0))
    percent = 100 * 6.0 / diagonal  # small loops are 4 long, large ones 12
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    assert genus_and_holes(obj) == (5, 0)
    bpy.ops.ed.undo_push(message="before")
    assert bpy.ops.topstoc.clean("EXEC_DEFAULT", True, max_handle=percent, max_hole=0.0) == {"FINISHED"}
    obj = bpy.data.objects[name]
    assert genus_and_holes(obj) == (1, 0)
    mesh = obj.data
    out = np.zeros(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", out)
    out = out.reshape(-1, 3)
    # Input vertices keep their ids; all but the cut loops' copies keep their positions (float32 in Blender).
    same = np.all(np.abs(out[:len(vertices)] - vertices) < 1e-6, axis=1)
    assert (~same).sum() <= 4 * 4 and len(out) > len(vertices)
    mesh.calc_loop_triangles()
    assert reference.aspect_ratios(out, np.array([t.vertices[:] for t in mesh.loop_triangles])).max() <= 5
    bpy.ops.ed.undo()
    obj = bpy.data.objects[name]
    assert len(obj.data.vertices) == len(vertices) and genus_and_holes(obj) == (5, 0)


def test_clean_fills_small_holes_only(ts, scene):
    vertices, triangles = cleanup_meshes.perforated_plate(6, 2, side=24, jitter=0.05, seed=12)
    obj = make_object("Plate", vertices, triangles)
    diagonal = np.linalg.norm(np.ptp(vertices, axis=0))
    assert bpy.ops.topstoc.clean(max_handle=0.0, max_hole=100 * 6.0 / diagonal) == {"FINISHED"}
    assert genus_and_holes(obj) == (0, 3)  # the plate's edge and the two large holes
