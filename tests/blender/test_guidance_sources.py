"""Each guidance source changes the sampling the documented way (topstoc.core.api.guidance)."""

import bpy
import numpy as np
import pytest

import meshgen
from helpers import Params, make_object, vertex_areas


def sphere(name="Sphere", subdivisions=4):
    vertices, faces = meshgen.icosphere(subdivisions)
    return make_object(name, vertices, faces), vertices, faces


def run(ts, obj, **params):
    return ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(**params))


def density_ratio(vertices, faces, kept, region):
    """(kept vertices per area inside region) / (per area outside)."""
    area = vertex_areas(vertices, faces)
    inside = np.zeros(len(vertices), dtype=bool)
    inside[np.asarray(kept)] = True
    per_area_in = inside[region].sum() / area[region].sum()
    per_area_out = inside[~region].sum() / area[~region].sum()
    return per_area_in / per_area_out


def paint(ts, obj, mask, u):
    """Paints guidance u on the masked vertices through the add-on's layer writer."""
    from importlib import import_module

    writer = import_module(ts.__name__ + ".blender.operators.guidance")
    writer.write_guidance(obj, np.asarray(mask, dtype=bool), None, u)


def test_painted_more_detail_keeps_denser_sampling(ts, scene):
    obj, v, f = sphere()
    half = v[:, 0] > 0.0
    paint(ts, obj, half, 0.5)  # "more": p = k + (1 - k) / 2
    r = run(ts, obj, ratio=0.05).result
    assert density_ratio(v, f, r.kept, half) >= 5.0


def test_painted_less_detail_keeps_sparser_sampling(ts, scene):
    obj, v, f = sphere()
    half = v[:, 0] > 0.0
    paint(ts, obj, half, -0.5)
    r = run(ts, obj, ratio=0.2).result
    assert density_ratio(v, f, r.kept, half) <= 0.7


def test_keep_and_drop_are_exact(ts, scene):
    obj, v, f = sphere()
    keep = v[:, 2] > 0.8
    drop = v[:, 2] < -0.5
    paint(ts, obj, keep, 1.0)
    paint(ts, obj, drop, -1.0)
    r = run(ts, obj, ratio=0.05).result
    kept = set(r.kept.tolist())
    assert set(np.flatnonzero(keep).tolist()) <= kept                  # u = 1: all kept
    assert len(kept & set(np.flatnonzero(drop).tolist())) <= r.stats.repairs  # u = -1: only if topology needs it


def test_colour_convention_round_trips(ts, scene):
    rules = ts.core.api.guidance
    for name, u in rules.GUIDANCE_LEVELS.items():
        colour = rules.guidance_color(u)
        assert rules.color_to_guidance(colour[None, :3])[0] == pytest.approx(u)
    obj, v, f = sphere(subdivisions=2)
    u = np.linspace(-1, 1, len(v))
    from importlib import import_module
    writer = import_module(ts.__name__ + ".blender.operators.guidance")
    for value in (-1.0, -0.5, 0.0, 0.5, 1.0):
        writer.write_guidance(obj, np.isclose(np.round(u * 2) / 2, value), None, value)
    read = ts.blender.decimation.guidance.read_color_guidance(obj.data, obj.topstoc.color_attribute)
    np.testing.assert_allclose(read, np.round(u * 2) / 2, atol=1e-6)


def test_vertex_group_mappings(ts, scene):
    obj, v, f = sphere()
    cap = np.flatnonzero(v[:, 2] > 0.7)
    group = obj.vertex_groups.new(name="Detail")
    group.add(cap.tolist(), 1.0, "REPLACE")
    obj.topstoc.use_vertex_group = True
    obj.topstoc.vertex_group = "Detail"
    r = run(ts, obj, ratio=0.05).result
    assert set(cap.tolist()) <= set(r.kept.tolist())  # DETAIL: weight 1 = keep
    group.add(cap.tolist(), 0.0, "REPLACE")
    obj.topstoc.vertex_group_mapping = "DECIMATE"   # Blender's convention: weight 0 locks
    r = run(ts, obj, ratio=0.05).result
    assert set(cap.tolist()) <= set(r.kept.tolist())
    group.add(cap.tolist(), 0.0, "REPLACE")
    obj.topstoc.vertex_group_mapping = "SIGNED"     # weight 0 = drop
    r = run(ts, obj, ratio=0.05).result
    assert len(set(cap.tolist()) & set(r.kept.tolist())) <= r.stats.repairs


def test_strength_scales_a_source(ts, scene):
    obj, v, f = sphere()
    half = v[:, 0] > 0.0
    paint(ts, obj, half, 1.0)
    obj.topstoc.color_strength = 0.5   # keep at half strength = "more"
    r = run(ts, obj, ratio=0.05).result
    inside = np.isin(np.flatnonzero(half), r.kept).mean()
    outside = np.isin(np.flatnonzero(~half), r.kept).mean()
    # u = 0.5 is "more", not a control point: nine times the density ((1 + u) / (1 - u))^2,
    # within the same budget (5 %)
    assert 5 < inside / outside < 13 and inside < 0.9, (inside, outside)
    assert abs(r.num_vertices - round(0.05 * len(v))) <= max(1, 0.01 * 0.05 * len(v))


def test_material_slot_weights_and_borders(ts, scene):
    obj, v, f = sphere()
    for name in ("Top", "Bottom"):
        obj.data.materials.append(bpy.data.materials.new(name))
    centroid_z = v[np.asarray(f)].mean(axis=1)[:, 2]
    slots = (centroid_z < 0).astype(np.int32)
    obj.data.polygons.foreach_set("material_index", slots)
    obj.data.update()
    obj.topstoc.material_weights[1] = -1.0   # bottom: drop
    r = run(ts, obj, ratio=0.1).result
    faces = np.asarray(f)
    on_top = np.zeros(len(v), dtype=bool)
    on_top[faces[slots == 0].ravel()] = True
    bottom_only = ~on_top
    assert len(set(np.flatnonzero(bottom_only).tolist()) & set(r.kept.tolist())) <= r.stats.repairs
    # Border: each output face lies inside one material region (all its vertices touch a face of it).
    touches = [np.zeros(len(v), dtype=bool) for _ in range(2)]
    for slot in (0, 1):
        touches[slot][faces[slots == slot].ravel()] = True
    out_slots = slots[r.face_source]
    corners = r.kept[r.triangles]
    for slot in (0, 1):
        assert touches[slot][corners[out_slots == slot]].all()


def test_box_empty_sets_guidance_inside(ts, scene):
    obj, v, f = sphere()
    box = bpy.data.objects.new("Box", None)
    box.empty_display_type = "CUBE"
    box.empty_display_size = 0.5
    box.location = (0.0, 0.0, 1.0)
    box.topstoc.box_enabled = True
    box.topstoc.box_weight = 1.0
    scene.collection.objects.link(box)
    bpy.context.view_layer.update()
    inside = np.all(np.abs(v - [0, 0, 1]) <= 0.5, axis=1)
    assert inside.sum() > 10
    r = run(ts, obj, ratio=0.05).result
    assert set(np.flatnonzero(inside).tolist()) <= set(r.kept.tolist())
    box.topstoc.box_weight = -1.0
    r = run(ts, obj, ratio=0.05).result
    assert len(set(np.flatnonzero(inside).tolist()) & set(r.kept.tolist())) <= r.stats.repairs


def test_camera_view_thins_back_faces(ts, scene):
    obj, v, f = sphere()
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.0, -6.0, 0.0)
    camera.rotation_euler = (np.pi / 2, 0.0, 0.0)   # looking along +y at the sphere
    scene.camera = camera
    bpy.context.view_layer.update()
    scene.topstoc.use_view = True
    scene.topstoc.back_ratio = 0.1
    scene.topstoc.silhouette_angle = 0.0
    scene.topstoc.silhouette_falloff = 0.0
    r = run(ts, obj, ratio=0.1).result
    front = v[:, 1] < -0.2
    back = v[:, 1] > 0.2
    kept = np.zeros(len(v), dtype=bool)
    kept[r.kept] = True
    area = vertex_areas(v, f)
    front_density = kept[front].sum() / area[front].sum()
    back_density = kept[back].sum() / area[back].sum()
    assert front_density >= 4 * back_density


def test_sharp_edges_are_borders(ts, scene):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24)  # has an equator of edges
    obj = bpy.context.object
    mesh = obj.data
    v = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", v)
    v = v.reshape(-1, 3).astype(float)
    edges = np.empty(2 * len(mesh.edges), dtype=np.int32)
    mesh.edges.foreach_get("vertices", edges)
    edges = edges.reshape(-1, 2)
    equator = np.all(np.abs(v[edges][:, :, 2]) < 1e-6, axis=1)
    assert equator.sum() == 48
    mesh.edges.foreach_set("use_edge_sharp", equator)
    obj.topstoc.use_sharp = True
    prepared_run = run(ts, obj, ratio=0.05)
    r = prepared_run.result
    tris = prepared_run.prepared.arrays.triangles
    z = v[r.kept[r.triangles]][:, :, 2]
    source_up = v[tris[r.face_source]][:, :, 2].mean(axis=1) > 0
    # No output triangle crosses the equator: each stays on its source face's side.
    assert np.all(z[source_up] >= -1e-6) and np.all(z[~source_up] <= 1e-6)
    obj.topstoc.use_sharp = False
    r = run(ts, obj, ratio=0.05).result
    z = v[r.kept[r.triangles]][:, :, 2]
    assert np.any((z.max(axis=1) > 1e-3) & (z.min(axis=1) < -1e-3))  # without the border some do


def test_direct_selection_in_edit_mode(ts, scene):
    obj, v, f = sphere()
    select = v[:, 0] > 0.8
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="OBJECT")
    obj.data.vertices.foreach_set("select", select)
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.context.tool_settings.mesh_select_mode = (True, False, False)
    assert bpy.ops.topstoc.set_guidance(level="KEEP") == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    u = ts.blender.decimation.guidance.read_color_guidance(obj.data, obj.topstoc.color_attribute)
    np.testing.assert_allclose(u[select], 1.0)
    np.testing.assert_allclose(u[~select], 0.0, atol=1e-6)
    r = run(ts, obj, ratio=0.02).result
    assert set(np.flatnonzero(select).tolist()) <= set(r.kept.tolist())


def test_missing_sources_are_reported_and_nothing_changes(ts, scene):
    obj, v, f = sphere(subdivisions=2)
    obj.topstoc.use_vertex_group = True
    obj.topstoc.vertex_group = "Nope"
    with pytest.raises(ts.blender.decimation.guidance.GuidanceError, match="vertex group 'Nope' not found"):
        run(ts, obj)
    with pytest.raises(RuntimeError, match="vertex group 'Nope' not found"):  # the operator's error report
        bpy.ops.topstoc.guided_decimate(ratio=0.5)
    obj.topstoc.use_vertex_group = False
    obj.topstoc.color_attribute = "Paint"
    with pytest.raises(ts.blender.decimation.guidance.GuidanceError, match="colour attribute 'Paint' not found"):
        run(ts, obj)
    assert [o.name for o in bpy.data.objects] == ["Sphere"]
    assert len(obj.data.vertices) == len(v)


def test_guidance_layer_and_palette(ts, scene):
    obj, v, f = sphere(subdivisions=1)
    assert bpy.ops.topstoc.add_guidance_layer() == {"FINISHED"}
    layer = obj.data.color_attributes[obj.topstoc.color_attribute]
    assert obj.data.color_attributes.active_color.name == layer.name
    u = ts.blender.decimation.guidance.read_color_guidance(obj.data, layer.name)
    np.testing.assert_allclose(u, 0.0, atol=1e-6)                       # created neutral grey
    palette = bpy.data.palettes["TopStoc Guidance"]
    rules = ts.core.api.guidance
    decoded = [rules.color_to_guidance(np.array(c.color)[None])[0] for c in palette.colors]
    np.testing.assert_allclose(decoded, [1.0, 0.5, 0.0, -0.5, -1.0], atol=1e-6)


def test_control_points_over_the_target_are_reported_on_the_result(ts, scene):
    """Issue 16: only control points (u = 1) may push the count over the target; the status line
    and the result object (which the panel reads) say by how much and why. A result within the
    target stores 0."""
    obj, v, f = sphere()
    keep = v[:, 2] > 0.3  # about a third of the sphere as control points, far over 5 %
    paint(ts, obj, keep, 1.0)
    pipeline = ts.blender.decimation.pipeline
    run = pipeline.decimate(bpy.context, obj, Params(ratio=0.05))
    over, reason = run.result.stats.over_budget, run.result.stats.over_budget_reason
    assert run.result.num_vertices >= keep.sum() > round(0.05 * len(v))
    assert over == run.result.num_vertices - round(0.05 * len(v)) and reason == "control points"
    out = pipeline.write_output(run)
    assert out["topstoc_over_budget"] == over and out["topstoc_over_budget_reason"] == reason
    target = round(0.05 * len(v))
    assert (f"target missed: {run.result.num_vertices:,} vertices for {target:,} ({over:,} over"
            in pipeline.summary(run)) and pipeline.summary(run).endswith("; control points)")
    assert out["topstoc_target_missed"] == run.result.stats.target_missed.text()
    plain, _, _ = sphere("Plain")
    out = pipeline.write_output(pipeline.decimate(bpy.context, plain, Params(ratio=0.05)))
    assert out["topstoc_over_budget"] == 0 and out["topstoc_over_budget_reason"] == ""
    assert out["topstoc_target_missed"] == ""
