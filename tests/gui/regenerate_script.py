"""Run by test_regenerate_gui.py in a windowed Blender under Xvfb: Auto Regenerate as an artist
meets it. Suzanne is decimated (Fast, so the result's vertices are source vertices), the result
is moved and given its own material, Auto is switched on; then the source is edited in Edit Mode
(three moves in quick succession) and the artist goes back to Object Mode. The result must
regenerate once, only after the debounce, from the edited source, and keep its own transform and
material. Checks + report.json."""

import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import session  # noqa: E402
from session import check, report  # noqa: E402

ADDON = session.enable_addon()


def positions(mesh):
    co = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def steps():
    regenerate = sys.modules[ADDON.__name__ + ".blender.preview.regenerate"]
    runs = []
    original = regenerate.regenerate

    def counted(context, result_obj):
        runs.append((time.perf_counter(), result_obj.name))
        return original(context, result_obj)

    regenerate.regenerate = counted  # the debounce timer looks it up at each call

    source = bpy.data.objects["Suzanne"]
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    source.select_set(True)
    bpy.context.view_layer.objects.active = source
    settings = bpy.context.scene.topstoc
    settings.quality, settings.target_mode, settings.ratio, settings.seed = "FAST", "RATIO", 0.3, 5
    with session.override():
        assert bpy.ops.topstoc.guided_decimate("INVOKE_DEFAULT") == {"FINISHED"}
    yield 0.3
    result = bpy.data.objects["Suzanne_TopStoc"]
    # the artist's own edits of the result: a transform and a material
    result.location = (4.0, -1.0, 0.5)
    result.rotation_euler = (0.0, 0.0, 0.6)
    own = bpy.data.materials.new("Result's own")
    result.data.materials.append(own)
    result.topstoc.auto_regenerate = True
    before = positions(result.data)
    yield 1.5
    check("nothing regenerates without a source edit", not runs, str(runs))
    matrix = [list(row) for row in result.matrix_world]  # evaluated by now

    # edit the source in Edit Mode: three moves of every vertex in quick succession
    result.select_set(False)
    source.select_set(True)
    bpy.context.view_layer.objects.active = source
    with session.override():
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.select_all(action="SELECT")
    for _ in range(3):
        with session.override():
            bpy.ops.transform.translate(value=(0.0, 0.0, 0.1))
        yield 0.2
    yield 1.5
    check("no regeneration while the source is in Edit Mode", not runs, str(runs))
    with session.override():
        bpy.ops.object.mode_set(mode="OBJECT")
    left_edit = time.perf_counter()
    yield 0.3
    check("none before the debounce", not runs, str(runs))
    waited = time.perf_counter()
    while not runs and time.perf_counter() - waited < 10:
        yield 0.05
    yield 2.0  # a second regeneration, if any, would come within this
    report["values"]["regenerations"] = len(runs)
    report["values"]["seconds_after_edit"] = runs[0][0] - left_edit if runs else None
    check("regenerated once after the debounce", len(runs) == 1 and runs[0][1] == "Suzanne_TopStoc"
          and runs[0][0] - left_edit >= regenerate.DEBOUNCE, str(report["values"]))

    # the result shows the edited source: its vertices are source vertices, 0.3 higher than before
    edited = positions(source.data)
    after = positions(result.data)
    lookup = {tuple(np.round(p, 5)) for p in edited}
    check("the result comes from the edited source", all(tuple(np.round(p, 5)) in lookup for p in after)
          and abs(after[:, 2].min() - before[:, 2].min() - 0.3) < 1e-4,
          f"{after[:, 2].min():.4f} vs {before[:, 2].min():.4f}")
    check("the result keeps its own transform",
          np.allclose([list(row) for row in result.matrix_world], matrix, atol=1e-6))
    check("the result keeps its own material", own.name in [m.name for m in result.data.materials if m])
    check("the source is untouched by the regeneration", len(source.data.vertices) == len(edited))
    regenerate.regenerate = original


session.run(steps)
