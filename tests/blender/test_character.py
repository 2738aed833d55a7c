"""A rigged, shape-keyed character through Guided Decimate: every shape key (values at kept
vertices, relative keys, slider ranges, mute, interpolation, vertex group), vertex groups,
parent, modifiers (the Armature still deforms the result like the source, checked on Blender's
own evaluated meshes), collection and custom properties, in every output mode, LOD chains and
the .blend batch."""

import json
import math

import bpy
import numpy as np
import pytest

from character import make_character
from conftest import DATA, PACKAGE
from helpers import Params, kept_ids, positions

KEY_SETTINGS = ("value", "slider_min", "slider_max", "mute", "interpolation", "vertex_group")


def key_table(mesh):
    """{name: (coordinates (n, 3), settings, relative key name)} of a mesh's shape keys."""
    table = {}
    for block in mesh.shape_keys.key_blocks:
        co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
        block.data.foreach_get("co", co)
        table[block.name] = (co.reshape(-1, 3), {s: getattr(block, s) for s in KEY_SETTINGS},
                             block.relative_key.name)
    return table


def group_weights(obj):
    """{group name: weight per vertex (0 where unassigned)}."""
    out = {g.name: np.zeros(len(obj.data.vertices)) for g in obj.vertex_groups}
    names = {g.index: g.name for g in obj.vertex_groups}
    for v in obj.data.vertices:
        for g in v.groups:
            out[names[g.group]][v.index] = g.weight
    return out


def evaluated_world(obj):
    """World positions of ``obj``'s evaluated mesh (shape keys + armature, Blender's evaluation)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    co = positions(mesh).astype(np.float64)
    evaluated.to_mesh_clear()
    matrix = np.array(evaluated.matrix_world)
    return co @ matrix[:3, :3].T + matrix[:3, 3]


def source_state(body):
    return dict(co=positions(body.data).copy(), keys=key_table(body.data), groups=group_weights(body),
                collections={c.name for c in body.users_collection},
                parent_inverse=np.array(body.matrix_parent_inverse))


def check_carried(state, out, rig, kept):
    keys = key_table(out.data)
    assert list(keys) == list(state["keys"])
    for name, (co, settings, relative) in state["keys"].items():
        out_co, out_settings, out_relative = keys[name]
        np.testing.assert_array_equal(out_co, co[kept], err_msg=name)
        assert out_settings == settings and out_relative == relative, name
    assert out.data.shape_keys.reference_key.name == "Basis"
    weights = group_weights(out)
    for name, w in state["groups"].items():
        np.testing.assert_allclose(weights[name], w[kept], atol=1e-6, err_msg=name)
    assert [(m.type, m.name) for m in out.modifiers] == [("ARMATURE", "Armature")]
    assert out.modifiers["Armature"].object == rig
    assert out.parent == rig
    np.testing.assert_allclose(np.array(out.matrix_parent_inverse), state["parent_inverse"])
    assert {c.name for c in out.users_collection} == state["collections"] == {"Characters"}
    assert out["asset_id"] == 42


@pytest.mark.parametrize("output", ["NEW_OBJECT", "IN_PLACE"])
def test_shape_keys_and_rig_follow_the_source(ts, scene, output):
    body, rig = make_character()
    state = source_state(body)
    source_name = body.name
    assert bpy.ops.topstoc.guided_decimate(ratio=0.3, output=output, quality="FAST") == {"FINISHED"}
    out = bpy.context.active_object if output == "NEW_OBJECT" else bpy.data.objects[source_name]
    if output == "NEW_OBJECT":
        assert out is not body and body.hide_get()  # a rigged original is hidden, not moved
        np.testing.assert_allclose(np.array(out.matrix_world), np.array(body.matrix_world))
    assert len(out.data.vertices) < 0.5 * len(state["co"])
    lookup = {tuple(p): i for i, p in enumerate(state["co"].tolist())}
    kept = np.array([lookup[tuple(p)] for p in positions(out.data).tolist()])
    check_carried(state, out, rig, kept)


def test_armature_deforms_the_result_like_the_source(ts, scene):
    body, rig = make_character()
    assert bpy.ops.topstoc.guided_decimate(ratio=0.3, output="NEW_OBJECT", quality="FAST") == {"FINISHED"}
    out = bpy.context.active_object
    kept = kept_ids(body.data, out.data)
    body.hide_set(False)  # hidden objects may be left out of the viewport's evaluation
    rest = evaluated_world(body)
    upper = rig.pose.bones["Upper"]
    upper.rotation_mode = "XYZ"
    upper.rotation_euler = (math.radians(50), 0, math.radians(20))
    rig.pose.bones["Lower"].rotation_mode = "XYZ"
    rig.pose.bones["Lower"].rotation_euler = (0, math.radians(-15), 0)
    bpy.context.view_layer.update()
    posed_source = evaluated_world(body)
    posed_out = evaluated_world(out)
    assert np.abs(posed_source - rest).max() > 0.3  # the pose moves the mesh, so the test can tell
    np.testing.assert_allclose(posed_out, posed_source[kept], atol=1e-5)


def test_filtered_placement_interpolates_each_keys_offset(ts, scene):
    """A moved vertex's offset (key minus position) is interpolated on the input surface it stands
    on: it lies within the offsets of one input triangle of its cluster (checked by brute force
    over that cluster's triangles); a vertex that did not move keeps its input key exactly.
    (tests/blender/test_moved_attributes.py checks the interpolation itself.)"""
    body, _rig = make_character()
    state = source_state(body)
    params = Params(ratio=0.3, quality="CUSTOM", placement="filtered", refine=0)
    run = ts.blender.pipeline.decimate(bpy.context, body, params)
    out = ts.blender.pipeline.write_output(run)
    kept = np.asarray(run.result.kept)
    out_co = positions(out.data).astype(np.float64)
    moved = np.flatnonzero(np.any(out_co != state["co"][kept], axis=1))
    assert np.abs(out_co - state["co"][kept]).max() > 1e-4 and len(moved)  # vertices did move
    still = np.setdiff1d(np.arange(len(kept)), moved)
    body.data.calc_loop_triangles()
    triangles = np.array([tuple(t.vertices) for t in body.data.loop_triangles])
    labels = np.asarray(run.result.labels)
    for name, (co, _settings, _relative) in key_table(out.data).items():
        np.testing.assert_array_equal(co[still], state["keys"][name][0][kept[still]], err_msg=name)
        source_offset = state["keys"][name][0].astype(np.float64) - state["co"]
        offset = co.astype(np.float64) - out_co
        for v in moved:
            cluster = np.flatnonzero(labels == v)
            candidates = triangles[np.isin(triangles, cluster).any(axis=1)]
            lo, hi = source_offset[candidates].min(axis=1), source_offset[candidates].max(axis=1)
            assert np.any(np.all((lo - 1e-5 <= offset[v]) & (offset[v] <= hi + 1e-5), axis=1)), (name, v)


def test_lod_chain_carries_shape_keys(ts, scene):
    body, rig = make_character()
    state = source_state(body)
    assert bpy.ops.topstoc.lod_chain(ratios="1.0, 0.4, 0.15", quality="FAST") == {"FINISHED"}
    lods = [bpy.data.objects[f"Body_LOD{i}"] for i in range(3)]
    for lod in lods:
        lookup = {tuple(p): i for i, p in enumerate(state["co"].tolist())}
        kept = np.array([lookup[tuple(p)] for p in positions(lod.data).tolist()])
        keys = key_table(lod.data)
        for name, (co, settings, relative) in state["keys"].items():
            np.testing.assert_array_equal(keys[name][0], co[kept])
            assert keys[name][1] == settings and keys[name][2] == relative
        assert lod.modifiers["Armature"].object == rig and lod["asset_id"] == 42


MAKE_CHARACTER = """
import sys, bpy
sys.path.insert(0, {tests!r})
from character import make_character
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
make_character()
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""


def test_blend_batch_keeps_shape_keys(ts, scene, tmp_path):
    import launch  # the Blender under test (binary or bpy module), in a clean environment

    source = tmp_path / "character.blend"
    code = MAKE_CHARACTER.format(tests=str(DATA.parent / "blender"), path=str(source))
    made = launch.background(expr=code, timeout=120)
    assert made.returncode == 0, made.stderr
    out_dir = tmp_path / "out"
    done = launch.background(PACKAGE / "batch.py", "--input", source, "--ratio", "0.3", "--mode", "fast",
                             "--output", out_dir, "--json", tmp_path / "report.json", timeout=300)
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["results"][0]["objects"][0]["object"] == "Body"
    try:
        bpy.ops.wm.open_mainfile(filepath=str(source))
        state = source_state(bpy.data.objects["Body"])
        bpy.ops.wm.open_mainfile(filepath=str(out_dir / "character.blend"))
    except RuntimeError as error:
        pytest.skip(f"this Blender cannot read the batch Blender's file: {error}")
    out = bpy.data.objects["Body"]
    lookup = {tuple(p): i for i, p in enumerate(state["co"].tolist())}
    kept = np.array([lookup[tuple(p)] for p in positions(out.data).tolist()])
    assert len(kept) < 0.5 * len(state["co"])
    check_carried(state, out, bpy.data.objects["Rig"], kept)
