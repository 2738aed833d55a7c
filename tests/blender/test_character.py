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
    run = ts.blender.decimation.pipeline.decimate(bpy.context, body, params)
    out = ts.blender.decimation.pipeline.write_output(run)
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


# -- quality mode: the skin of moved vertices -------------------------------------------------------

POSE = {"Upper": (math.radians(60), 0, math.radians(25)), "Lower": (0, math.radians(-20), 0)}


def pose(rig, angles):
    for name, euler in angles.items():
        bone = rig.pose.bones[name]
        bone.rotation_mode = "XYZ"
        bone.rotation_euler = euler
    bpy.context.view_layer.update()


def loop_triangles(mesh):
    mesh.calc_loop_triangles()
    triangles = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return triangles.reshape(-1, 3)


def nearest_surface_points(points, vertices, triangles):
    """(triangle, barycentric weights) of the point of the surface nearest each point, by brute
    force over every triangle: the projection onto its plane when it falls inside, else the
    nearest point of its three edges."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    found_triangle, found_weights = [], []
    for p in points:
        e0, e1, d = b - a, c - a, p - a
        d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
        d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
        det = d00 * d11 - d01 * d01
        s, t = (d11 * d20 - d01 * d21) / det, (d00 * d21 - d01 * d20) / det
        candidates = [np.stack([1 - s - t, s, t], axis=1)]
        inside = (s >= 0) & (t >= 0) & (s + t <= 1)
        for i, j in ((0, 1), (1, 2), (2, 0)):  # edges: clamp the projection onto the segment
            u, v = (a, b, c)[i], (a, b, c)[j]
            f = np.clip(((p - u) * (v - u)).sum(1) / ((v - u) * (v - u)).sum(1), 0, 1)
            w = np.zeros((len(a), 3))
            w[:, i], w[:, j] = 1 - f, f
            candidates.append(w)
        best_distance, best_weights = None, None
        for k, w in enumerate(candidates):
            point = w[:, :1] * a + w[:, 1:2] * b + w[:, 2:] * c
            distance = np.linalg.norm(point - p, axis=1)
            if k == 0:
                distance = np.where(inside, distance, np.inf)
            if best_distance is None:
                best_distance, best_weights = distance, w
            else:
                closer = distance < best_distance
                best_distance = np.where(closer, distance, best_distance)
                best_weights = np.where(closer[:, None], w, best_weights)
        nearest = int(np.argmin(best_distance))
        found_triangle.append(nearest)
        found_weights.append(best_weights[nearest])
    return np.array(found_triangle), np.array(found_weights)


def replace_weights(obj, vertices, weights):
    """Sets the vertex-group weights of ``vertices`` to ``weights`` ({group: per-vertex weight})."""
    for group in obj.vertex_groups:
        group.remove([int(v) for v in vertices])
        for v, w in zip(vertices.tolist(), weights[group.name].tolist()):
            if w > 0:
                group.add([v], w, "REPLACE")


class SkinReference:
    """The source character's surface at rest and posed (Blender's own evaluation: shape keys and
    armature), to compare results' moved vertices with, at their nearest surface point."""

    def __init__(self, body, rig):
        self.co = positions(body.data).astype(np.float64)
        self.triangles = loop_triangles(body.data)
        body.hide_set(False)  # hidden objects may be left out of the viewport's evaluation
        pose(rig, {name: (0, 0, 0) for name in POSE})
        self.rest = evaluated_world(body)
        pose(rig, POSE)
        self.posed = evaluated_world(body)
        pose(rig, {name: (0, 0, 0) for name in POSE})
        self.groups = group_weights(body)
        assert np.abs(self.posed - self.rest).max() > 0.4  # the pose moves the mesh, so the test can tell

    def blend(self, out):
        """Output vertices whose nearest source surface point (brute force) lies in the blend
        between the bones (a corner of its triangle weighted to both), with that point's
        (triangle, barycentric weights)."""
        co = positions(out.data).astype(np.float64)
        triangle, weights = nearest_surface_points(co, self.co, self.triangles)
        corner_upper = self.groups["Upper"][self.triangles[triangle]]
        blended = np.flatnonzero(((corner_upper > 0) & (corner_upper < 1)).any(axis=1))
        return blended, triangle[blended], weights[blended]

    def errors(self, out, rig, moved, triangle, weights):
        """(rest, posed) distance of each moved vertex from the source surface's point with the
        same barycentric coordinates (both evaluated with shape keys; posed also with the rig)."""
        pose(rig, {name: (0, 0, 0) for name in POSE})
        rest = evaluated_world(out)[moved]
        pose(rig, POSE)
        posed = evaluated_world(out)[moved]
        pose(rig, {name: (0, 0, 0) for name in POSE})
        corners = self.triangles[triangle]
        rest_reference = np.einsum("kj,kjd->kd", weights, self.rest[corners])
        posed_reference = np.einsum("kj,kjd->kd", weights, self.posed[corners])
        return np.linalg.norm(rest - rest_reference, axis=1), np.linalg.norm(posed - posed_reference, axis=1)


def check_skin(reference, out, rig, label):
    """Posed, a result's vertices in the blend stay with the posed source surface at their nearest
    point: the pose adds little to their rest distance from it (at most 1 % of the character's
    height). Returns (vertex ids, triangles, barycentric weights, rest and posed distances)."""
    ids, triangle, weights = reference.blend(out)
    assert len(ids) >= 5, (label, len(ids))
    rest, posed = reference.errors(out, rig, ids, triangle, weights)
    assert posed.max() <= rest.max() + 0.02, (label, posed.max(), rest.max())
    out_weights = group_weights(out)
    sums = out_weights["Lower"][ids] + out_weights["Upper"][ids]
    np.testing.assert_allclose(sums, 1.0, atol=1e-5, err_msg=label)  # the source's skin is normalised
    return ids, triangle, weights, rest, posed


@pytest.mark.parametrize("ratio", [0.3, 0.1])
def test_moved_vertices_interpolate_the_skin(ts, scene, ratio):
    """Posed with the armature, the result's moved vertices stay with the source surface at their
    nearest point (brute force), clearly closer than with the kept vertex's weights (the old
    copying, rebuilt on a copy of the result for comparison). The quality mode's collapses put
    many vertices onto other input vertices (all of them in the blend at 30 %) and some between
    them (at 10 %)."""
    body, rig = make_character()
    reference = SkinReference(body, rig)
    run = ts.blender.decimation.pipeline.decimate(bpy.context, body, Params(ratio=ratio, quality="QUALITY"))
    out = ts.blender.decimation.pipeline.write_output(run)
    ids, triangle, weights, rest, posed = check_skin(reference, out, rig, "quality")
    # moved vertices: not at their kept input vertex (many stand on another input vertex after a collapse)
    kept = np.asarray(run.result.kept)
    moved = np.any(np.asarray(run.result.vertices) != reference.co[kept], axis=1)[ids]
    assert moved.sum() >= 5, moved.sum()
    ids, triangle, weights, rest, posed = ids[moved], triangle[moved], weights[moved], rest[moved], posed[moved]
    # the weights themselves: the mix at the nearest point (where the add-on found that same point)
    out_weights = group_weights(out)
    expected_upper = np.einsum("kj,kj->k", weights, reference.groups["Upper"][reference.triangles[triangle]])
    same = np.abs(expected_upper - out_weights["Upper"][ids]) <= 1e-5
    assert same.mean() >= 0.8, same.mean()
    # the old weights: each moved vertex took its kept input vertex's
    old = out.copy()
    old.data = out.data.copy()
    bpy.data.collections["Characters"].objects.link(old)
    replace_weights(old, ids, {name: w[kept[ids]] for name, w in reference.groups.items()})
    old_rest, old_posed = reference.errors(old, rig, ids, triangle, weights)
    # (at rest too: the Twist key acts through the Upper group's weights)
    print(f"\nskin of {len(ids)} moved vertices in the blend: posed distance mean {posed.mean():.4f} max "
          f"{posed.max():.4f} (rest {rest.mean():.4f} / {rest.max():.4f}); with the kept vertex's weights: "
          f"mean {old_posed.mean():.4f} max {old_posed.max():.4f} (rest {old_rest.mean():.4f} / {old_rest.max():.4f})")
    assert posed.mean() <= 0.5 * old_posed.mean(), (posed.mean(), old_posed.mean())
    assert posed.max() <= 0.5 * old_posed.max(), (posed.max(), old_posed.max())


def test_lod_chain_and_multiview_interpolate_the_skin(ts, scene):
    body, rig = make_character()
    reference = SkinReference(body, rig)
    assert bpy.ops.topstoc.lod_chain(ratios="0.4, 0.2", quality="QUALITY") == {"FINISHED"}
    bpy.context.view_layer.objects.active = body
    body.select_set(True)
    assert bpy.ops.topstoc.multiview(count=2, ratio=0.3, variance=0.2, quality="QUALITY") == {"FINISHED"}
    for name in ("Body_LOD0", "Body_LOD1", "Body_MV1", "Body_MV2"):
        out = bpy.data.objects[name]
        out.matrix_world = body.matrix_world.copy()  # laid out beside the source: back onto the rig
        check_skin(reference, out, rig, name)


def test_blend_batch_lod_chain_interpolates_the_skin(ts, scene, tmp_path):
    import launch

    source = tmp_path / "character.blend"
    made = launch.background(expr=MAKE_CHARACTER.format(tests=str(DATA.parent / "blender"), path=str(source)),
                             timeout=120)
    assert made.returncode == 0, made.stderr
    out_dir = tmp_path / "out"
    done = launch.background(PACKAGE / "batch.py", "--input", source, "--ratio", "0.4", "0.2", "--mode", "quality",
                             "--output", out_dir, timeout=300)
    assert done.returncode == 0, done.stderr
    try:
        bpy.ops.wm.open_mainfile(filepath=str(source))
        reference = SkinReference(bpy.data.objects["Body"], bpy.data.objects["Rig"])  # arrays only: kept
        bpy.ops.wm.open_mainfile(filepath=str(out_dir / "character.blend"))
    except RuntimeError as error:
        pytest.skip(f"this Blender cannot read the batch Blender's file: {error}")
    rig = bpy.data.objects["Rig"]
    for name in ("Body_LOD0", "Body_LOD1"):
        check_skin(reference, bpy.data.objects[name], rig, name)
