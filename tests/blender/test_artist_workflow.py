"""The artist's workflow around Guided Decimate: where the output goes (beside the original, in
its collection), explicit operator properties over the panel's settings, why a button is
greyed out (poll messages), Regenerate after a source edit (by hand and automatically),
presets, the Quality choice, symmetry and the face-count estimate."""

import ast
import os
import time

import bpy
import numpy as np
import pytest

import meshgen
from conftest import DATA
from helpers import kept_ids, make_object, positions, select_only


def ball(name="Ball", collection=None):
    v, f = meshgen.icosphere(3)
    return make_object(name, v, f, collection)


def bbox_width_x(obj):
    xs = [(obj.matrix_world @ __import__("mathutils").Vector(c)).x for c in obj.bound_box]
    return max(xs) - min(xs)


def test_new_object_goes_beside_the_original_in_its_collection(ts, scene):
    props = bpy.data.collections.new("Props")
    scene.collection.children.link(props)
    obj = ball(collection=props)
    obj.location = (1.0, 2.0, 3.0)
    bpy.context.view_layer.update()
    assert bpy.ops.topstoc.guided_decimate(ratio=0.2) == {"FINISHED"}
    out = bpy.context.active_object
    assert out is not obj and not obj.hide_get()
    assert [c.name for c in out.users_collection] == ["Props"]
    assert out.location.x == pytest.approx(1.0 + 1.1 * bbox_width_x(obj), abs=1e-5)
    assert tuple(out.location)[1:] == pytest.approx((2.0, 3.0))


def test_explicit_properties_win_over_the_scene(ts, scene):
    """fill_from_scene (what invoke runs) keeps the properties a call set. Background Blender
    runs exec even for INVOKE_DEFAULT (no window), so the real invoke is checked in the GUI
    test (tests/gui/artist_script.py: 'explicit output wins on invoke')."""
    settings = scene.topstoc
    settings.output, settings.ratio, settings.seed = "NEW_OBJECT", 0.5, 7

    class Call:  # an operator called with output='IN_PLACE'
        class properties:
            @staticmethod
            def is_property_set(name):
                return name == "output"

    call = Call()
    call.output = "IN_PLACE"
    ts.blender.props.fill_from_scene(call, settings)
    assert call.output == "IN_PLACE" and call.ratio == pytest.approx(0.5) and call.seed == 7
    # operators do not remember their last call, so a property left out is never "set"
    ratio = bpy.ops.topstoc.guided_decimate.get_rna_type().properties["ratio"]
    assert ratio.is_skip_save


@pytest.mark.parametrize("operator, setup, message", [
    ("guided_decimate", "nothing", "Select one or more mesh objects"),
    ("guided_decimate", "edit", "Switch to Object Mode first"),
    ("lod_chain", "empty", "is not a mesh"),
    ("regenerate", "plain", "is not a TopStoc result"),
    ("cut_loop", "plain", "No active loop"),
    ("loop_step", "plain", "press Find Loops first"),
    ("restore_samples", "plain", "no saved samples"),
    ("write_error_colors", "plain", "Measure first"),
])
def test_greyed_out_buttons_say_why(ts, scene, operator, setup, message):
    if not hasattr(bpy.types.Operator, "poll_message_set"):
        pytest.skip("Blender before 3.0 has no poll messages")
    if setup == "empty":
        empty = bpy.data.objects.new("Empty", None)
        scene.collection.objects.link(empty)
        select_only(empty)
    elif setup in ("plain", "edit"):
        ball()
        if setup == "edit":
            bpy.ops.object.mode_set(mode="EDIT")
    else:
        for obj in scene.objects:
            obj.select_set(False)
    try:
        op = getattr(bpy.ops.topstoc, operator)
        assert not op.poll()
        with pytest.raises(RuntimeError, match=message):
            op()
    finally:
        if setup == "edit":
            bpy.ops.object.mode_set(mode="OBJECT")


def test_regenerate_after_a_source_edit_keeps_the_results_own_edits(ts, scene):
    obj = ball()
    bpy.ops.topstoc.guided_decimate(ratio=0.2, seed=3, quality="FAST")
    out = bpy.context.active_object
    first = positions(out.data).copy()
    material = bpy.data.materials.new("ArtistChoice")
    out.data.materials.append(material)
    out.location = (5.0, 0.0, 0.0)
    out.rotation_euler = (0.0, 0.0, 1.0)
    out.modifiers.new("Bevel", "BEVEL")
    # the same source regenerates the same mesh (the seed is part of the settings)
    assert bpy.ops.topstoc.regenerate() == {"FINISHED"}
    np.testing.assert_array_equal(positions(out.data), first)
    # edit the source: move every vertex
    co = positions(obj.data) * np.array([2.0, 1.0, 0.5], dtype=np.float32)
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    select_only(out)
    assert bpy.ops.topstoc.regenerate() == {"FINISHED"}
    kept = kept_ids(obj.data, out.data)
    np.testing.assert_array_equal(positions(out.data), co[kept])
    assert abs(len(kept) - len(first)) <= 0.05 * len(first)
    assert list(out.data.materials) == [material]
    assert tuple(out.location) == (5.0, 0.0, 0.0) and out.rotation_euler.z == pytest.approx(1.0)
    assert [m.name for m in out.modifiers] == ["Bevel"]
    assert out.topstoc.source == obj


def test_auto_regenerate_is_debounced(ts, scene):
    regenerate = ts.blender.preview.regenerate
    obj = ball()
    bpy.ops.topstoc.guided_decimate(ratio=0.2, quality="FAST")
    out = bpy.context.active_object
    out.topstoc.auto_regenerate = True
    co = positions(obj.data) * 1.5
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.context.view_layer.update()  # Blender reports the geometry update to the handler
    assert out.name in regenerate._pending
    before = positions(out.data).copy()
    assert regenerate.run_pending(now=time.monotonic()) is not None  # too soon: still waiting
    np.testing.assert_array_equal(positions(out.data), before)
    assert regenerate.run_pending(now=time.monotonic() + 2 * regenerate.DEBOUNCE) is None
    np.testing.assert_allclose(positions(out.data), 1.5 * before, rtol=1e-6)
    assert bpy.app.timers.is_registered(regenerate.run_pending)  # the handler started the timer
    bpy.app.timers.unregister(regenerate.run_pending)  # no event loop here to run it


def preset_values(path):
    """{setting: value} a preset file assigns (read with ast, not by running it)."""
    values = {}
    for node in ast.parse(open(path).read()).body:
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Attribute):
            values[node.targets[0].attr] = ast.literal_eval(node.value)
    return values


def test_presets_are_installed_and_apply(ts, scene):
    presets = ts.blender.ui.presets
    folder = presets.user_preset_folder()
    names = sorted(n for n in os.listdir(presets.BUNDLED) if n.endswith(".py"))
    assert {"Game_LOD.py", "Scan_Clean-up.py", "Hard_Surface.py"} <= set(names)
    for name in names:
        path = os.path.join(folder, name)
        assert os.path.exists(path)
        assert bpy.ops.script.execute_preset(filepath=path, menu_idname="TOPSTOC_MT_presets") == {"FINISHED"}
        for setting, value in preset_values(path).items():
            actual = getattr(scene.topstoc, setting)
            assert actual == (pytest.approx(value) if isinstance(value, float) else value), (name, setting)
    assert bpy.types.TOPSTOC_MT_presets.preset_subdir == presets.PRESET_SUBDIR


def test_quality_choice_maps_onto_engine_options(ts, scene):
    pipeline = ts.blender.decimation.pipeline
    settings = scene.topstoc
    for quality, mode in (("FAST", "fast"), ("QUALITY", "quality"), ("BEST", "best")):
        settings.quality = quality
        options = pipeline.decimate_options(settings)
        assert options["mode"] == mode and "placement" not in options and "refine" not in options
    settings.quality = "CUSTOM"  # the Advanced placement and refinement apply, on fast mode
    options = pipeline.decimate_options(settings)
    assert (options["mode"], options["placement"], options["refine"]) == ("fast", settings.placement,
                                                                          float(settings.refine))
    settings.quality = "QUALITY"
    import json

    obj = ball()
    outputs = {}
    for quality in ("FAST", "QUALITY"):
        select_only(obj)
        bpy.ops.topstoc.guided_decimate(ratio=0.2, quality=quality)
        outputs[quality] = bpy.context.active_object
    parameters = json.loads(outputs["QUALITY"]["topstoc_parameters"])
    assert parameters["mode"] == "quality"
    assert json.loads(outputs["FAST"]["topstoc_parameters"])["mode"] == "fast"
    fast, quality = (positions(outputs[q].data) for q in ("FAST", "QUALITY"))
    assert len(fast) != len(quality) or not np.array_equal(fast, quality)  # not the same run


@pytest.mark.parametrize("quality", ["FAST", "QUALITY"])
def test_symmetry_gives_a_mirror_symmetric_result(ts, scene, quality):
    bpy.ops.wm.obj_import(filepath=str(DATA / "open_boundary/kivy_suzanne_monkey.obj"))
    obj = bpy.context.selected_objects[0]
    select_only(obj)
    source = positions(obj.data)
    source[:, 0] -= 0.5 * (source[:, 0].min() + source[:, 0].max())  # mirror plane onto x = 0
    obj.data.vertices.foreach_set("co", source.ravel())
    obj.data.update()
    source = source.astype(np.float64)
    diagonal = np.linalg.norm(source.max(0) - source.min(0))

    def gap(co):
        mirrored = co * np.array([-1.0, 1.0, 1.0])
        return np.linalg.norm(co[None] - mirrored[:, None], axis=2).min(axis=1).max()

    assert gap(source) < 1e-5 * diagonal  # the input is symmetric about X
    bpy.ops.topstoc.guided_decimate(ratio=0.2, quality=quality, use_symmetry=True, symmetry_axis="X")
    out = positions(bpy.context.active_object.data).astype(np.float64)
    assert gap(out) <= 1e-5 * diagonal
    bpy.ops.topstoc.guided_decimate(ratio=0.2, quality=quality, use_symmetry=False)
    plain = positions(bpy.context.active_object.data).astype(np.float64)
    assert gap(plain) > 1e-3 * diagonal


def test_face_count_estimate_matches_the_result(ts, scene):
    obj = ball()
    settings = scene.topstoc
    pipeline = ts.blender.decimation.pipeline
    for mode, field, value in (("RATIO", "ratio", 0.2), ("VERTICES", "vertices", 150), ("TRIANGLES", "triangles", 300)):
        settings.target_mode = mode
        setattr(settings, field, value)
        estimate = pipeline.face_estimate(settings, obj.data)
        select_only(obj)
        bpy.ops.topstoc.guided_decimate(target_mode=mode, **{field: value})
        actual = len(bpy.context.active_object.data.polygons)
        assert abs(estimate - actual) <= 0.05 * actual, (mode, estimate, actual)
    settings.target_mode = "MAX_ERROR"
    assert pipeline.face_estimate(settings, obj.data) is None


def test_topology_help_covers_every_figure_and_loop_kind(ts, scene):
    import importlib

    help_text = importlib.import_module(f"{ts.__name__}.blender.ui.topology_help").HELP
    panel = importlib.import_module(f"{ts.__name__}.blender.ui.topology")
    obj = make_object("Torus", *meshgen.torus(24, 12))
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    rows = panel.help_rows(obj.topstoc.topology)
    topics = [topic for _label, _value, topic in rows if topic]
    assert len(topics) >= 11 and all(topic in help_text for topic in topics)
    explain = bpy.types.TOPSTOC_OT_explain
    for topic in topics + ["handle", "tunnel", "cut", "remove", "why", "repairs"]:
        props = type("P", (), {"topic": topic})()
        assert explain.description(bpy.context, props) == help_text[topic]
    assert "handle" in help_text["genus"].lower() and "print" in help_text["why"]
    summary = panel.plain_summary(obj.topstoc.topology)  # a closed torus: one handle, printable
    assert "1 handle" in summary and "ready to print" in summary
    kinds = {item.identifier: item.description
             for item in ts.blender.props.results.TOPSTOC_PG_loop.bl_rna.properties["kind"].enum_items}
    assert "ring on a finger" in kinds["HANDLE"] and "thread through a ring" in kinds["TUNNEL"]
    assert "genus drops" in bpy.ops.topstoc.remove_loop.get_rna_type().description
