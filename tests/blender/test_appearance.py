"""The add-on puts the look into Quality mode's cost: the active UV map and the appearance colour
go to the engine as attributes (Advanced > Appearance, 0 = off), the guidance paint never.

Effects are measured, not mocked: the UV-seamed cylinder of tests/uv_cylinder.py has its texture
stretched along the straight axis, and the UV error of a result is measured against the
cylinder's closed-form mapping."""

import json

import bpy
import numpy as np
import pytest

from helpers import make_object, positions, select_only
from uv_cylinder import uv_cylinder, uv_distortion

TARGET = 150  # vertices, of 1920


def cylinder(name="Cylinder", uv_maps=("Stretched",)):
    """The cylinder as a Blender object; each named UV map holds the stretched mapping, except
    "Plain", which is constant (no information for the cost)."""
    vertices, triangles, uvs = uv_cylinder()
    obj = make_object(name, vertices, triangles)
    for map_name in uv_maps:
        layer = obj.data.uv_layers.new(name=map_name)
        values = np.zeros_like(uvs) if map_name == "Plain" else uvs
        layer.data.foreach_set("uv", values.astype(np.float32).ravel())
    return obj


def paint(obj, name):
    """A point colour stretched along the axis like the texture, made the active colour."""
    mesh = obj.data
    z = positions(mesh)[:, 2].astype(np.float64)
    level = (z / 2.0) ** 3
    layer = mesh.color_attributes.new(name, "FLOAT_COLOR", "POINT")
    layer.data.foreach_set("color", np.c_[level, level, level, np.ones_like(level)].astype(np.float32).ravel())
    mesh.color_attributes.active_color = layer
    return layer


def decimate(obj, **options):
    """The operator's result (a new object) for ``obj``, Quality mode, TARGET vertices."""
    select_only(obj)
    assert bpy.ops.topstoc.guided_decimate(target_mode="VERTICES", vertices=TARGET, quality="QUALITY",
                                           **options) == {"FINISHED"}
    out = bpy.context.active_object
    assert out is not obj and len(out.data.vertices) == TARGET
    return out


def uv_error(out, name="Stretched"):
    mesh = out.data
    triangles = np.array([tuple(p.vertices) for p in mesh.polygons])
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    mesh.uv_layers[name].data.foreach_get("uv", uv)
    return uv_distortion(positions(mesh), triangles, uv.reshape(-1, 3, 2))


def test_the_active_uv_map_keeps_the_texture_in_place(ts, scene):
    obj = cylinder()
    kept = decimate(obj)
    off = decimate(obj, attribute_weight=0.0)
    with_uvs, without = uv_error(kept), uv_error(off)
    assert with_uvs["rms"] < 0.5 * without["rms"], (with_uvs, without)
    print(f"UV error at {TARGET} vertices: rms {with_uvs['rms']:.4f} with UVs, {without['rms']:.4f} without")
    # the result records what entered the cost
    parameters = json.loads(kept["topstoc_parameters"])
    assert parameters["attributes"] == ["UV map 'Stretched'"]
    assert parameters["attribute_weight"] == pytest.approx(ts.blender.decimation.pipeline.ATTRIBUTE_WEIGHT)
    assert json.loads(off["topstoc_parameters"])["attributes"] == []


def test_only_the_active_uv_map_counts(ts, scene):
    obj = cylinder(uv_maps=("Stretched", "Plain"))
    obj.data.uv_layers.active = obj.data.uv_layers["Plain"]
    plain_active = uv_error(decimate(obj))
    obj.data.uv_layers.active = obj.data.uv_layers["Stretched"]
    stretched_active = uv_error(decimate(obj))
    assert stretched_active["rms"] < 0.5 * plain_active["rms"], (stretched_active, plain_active)


def test_weight_zero_is_the_geometry_only_result(ts, scene):
    obj = cylinder()
    out = decimate(obj, attribute_weight=0.0)
    vertices, triangles, uvs = uv_cylinder()
    seams = ts.core.carry.attributes.uv_seam_edges(triangles, uvs)
    mesh = ts.core.Mesh(positions(obj.data).astype(np.float64), triangles)
    plain = mesh.decimate(target_vertices=TARGET, borders=seams, mode="quality", seed=0, adaptivity=0.5)
    np.testing.assert_array_equal(positions(out.data), plain.vertices.astype(np.float32))
    assert len(out.data.polygons) == plain.num_triangles


@pytest.mark.parametrize("layer, guidance_setting", [
    ("TopStoc Guidance", None),  # the add-on's own guidance layer
    ("Detail", "Detail"),        # a layer the object's Painted Guidance reads
])
def test_guidance_paint_is_never_appearance(ts, scene, layer, guidance_setting):
    reference = positions(decimate(cylinder("Bare", uv_maps=())).data)
    obj = cylinder("Painted", uv_maps=())
    obj.topstoc.use_color = False  # so the paint does not act as guidance either: only its name counts
    if guidance_setting is not None:
        obj.topstoc.color_attribute = guidance_setting
    paint(obj, layer)
    np.testing.assert_array_equal(positions(decimate(obj).data), reference)
    # the same colours under another name are appearance, and change the result
    obj.data.color_attributes[layer].name = "Tint"
    tinted = decimate(obj)
    assert not np.array_equal(positions(tinted.data), reference)
    assert json.loads(tinted["topstoc_parameters"])["attributes"] == ["colours 'Tint'"]


def test_fast_mode_passes_nothing(ts, scene):
    obj = cylinder()
    select_only(obj)
    runs = []
    for weight in (0.0, 1.0):
        assert bpy.ops.topstoc.guided_decimate(target_mode="VERTICES", vertices=TARGET, quality="FAST",
                                               attribute_weight=weight) == {"FINISHED"}
        runs.append(positions(bpy.context.active_object.data))
        select_only(obj)
    np.testing.assert_array_equal(runs[0], runs[1])


def test_restored_samples_reproduce_a_result_that_kept_the_uvs(ts, scene):
    obj = cylinder()
    first = positions(decimate(obj).data)
    assert json.loads(obj.topstoc.sample_sets["Last"].parameters)["attributes"] == ["UV map 'Stretched'"]
    select_only(obj)
    assert bpy.ops.topstoc.restore_samples(name="Last") == {"FINISHED"}
    np.testing.assert_array_equal(positions(bpy.data.objects["Cylinder_Last"].data), first)


def test_regenerate_keeps_the_weight_a_result_ran_with(ts, scene):
    obj = cylinder()
    kept = decimate(obj)
    off = decimate(obj, attribute_weight=0.0)
    first = {out.name: positions(out.data) for out in (kept, off)}
    assert json.loads(off.topstoc.settings)["attribute_weight"] == 0.0
    legacy = decimate(obj, attribute_weight=0.0)  # as a result saved before the setting existed
    settings = json.loads(legacy.topstoc.settings)
    del settings["attribute_weight"]
    legacy.topstoc.settings = json.dumps(settings)
    for out in (kept, off, legacy):
        select_only(out)
        assert bpy.ops.topstoc.regenerate() == {"FINISHED"}
    np.testing.assert_array_equal(positions(kept.data), first[kept.name])
    np.testing.assert_array_equal(positions(off.data), first[off.name])
    np.testing.assert_array_equal(positions(legacy.data), first[off.name])


def test_guidance_paint_is_never_the_results_display_colour(ts, scene):
    """Issue 38: the guidance layer, active for painting, became the result's active and render
    colour, so an exported LOD showed the orange paint. A new result does not carry it (the source
    keeps it, Regenerate reads it there); another colour attribute is shown instead."""
    obj = cylinder("Painted", uv_maps=())
    paint(obj, "Tint")
    paint(obj, "TopStoc Guidance")  # painted last: the active one, as after painting
    colors = obj.data.color_attributes
    colors.render_color_index = list(colors).index(colors["TopStoc Guidance"])
    assert colors.active_color.name == "TopStoc Guidance"
    out = decimate(obj).data.color_attributes
    assert [a.name for a in out] == ["Tint"]
    assert out.active_color.name == "Tint" and out[out.render_color_index].name == "Tint"
    assert "TopStoc Guidance" in obj.data.color_attributes  # the source keeps its paint
    # in place, the object keeps its paint, but shows its own colours
    select_only(obj)
    assert bpy.ops.topstoc.guided_decimate(target_mode="VERTICES", vertices=TARGET, output="IN_PLACE") == {"FINISHED"}
    colors = obj.data.color_attributes
    assert {a.name for a in colors} == {"Tint", "TopStoc Guidance"}
    assert colors.active_color.name == "Tint" and colors[colors.render_color_index].name == "Tint"
