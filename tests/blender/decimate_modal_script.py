"""Run by test_decimate_modal.py in a windowed Blender under Xvfb with --enable-event-simulate:
Guided Decimate as a modal run on a worker thread (operators/decimate.py). Esc while the mesh is
prepared changes nothing and adds no undo step; a run to the end writes what the immediate run
(execute) writes, in one undo step. Prints one line per check and exits 0 only when all hold."""

import os
import sys
import threading
import traceback

import addon_utils
import bpy

sys.path.insert(0, os.environ["TOPSTOC_BUILD_PYTHON"])
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from windowed_steps import Checks, view3d  # noqa: E402

checks = Checks("decimate")
check = checks.check


def mesh_state(mesh):
    return [tuple(v.co) for v in mesh.vertices], [tuple(p.vertices) for p in mesh.polygons]


def gate_preparation(background):
    """Holds the worker at its first preparation report until the returned event is set."""
    reached, release = threading.Event(), threading.Event()
    original = background.BackgroundDecimation._preparing

    def preparing(job, index):
        told = original(job, index)

        def held(fraction, stage):
            reached.set()
            release.wait(30)
            return told(fraction, stage)
        return held

    background.BackgroundDecimation._preparing = preparing
    return reached, release, lambda: setattr(background.BackgroundDecimation, "_preparing", original)


def normal_map_image(obj):
    """The image the result's first material feeds its Normal Map node with (None: no map)."""
    if not obj.material_slots or obj.material_slots[0].material is None:
        return None
    for node in obj.material_slots[0].material.node_tree.nodes:
        if node.type == "NORMAL_MAP" and node.inputs["Color"].links:
            return node.inputs["Color"].links[0].from_node.image
    return None


def steps():
    window, area, region = view3d()
    override = dict(window=window, area=area, region=region)
    torus = bpy.data.objects["Torus"]
    torus.select_set(True)
    bpy.context.view_layer.objects.active = torus
    settings = bpy.context.scene.topstoc
    settings.ratio, settings.quality = 0.1, "QUALITY"
    decimate.BACKGROUND_TRIANGLES = 0  # this small torus runs as a big mesh would
    shown = []  # what the modal put in the header and status bar
    status = decimate.TOPSTOC_OT_guided_decimate._status
    decimate.TOPSTOC_OT_guided_decimate._status = lambda op, context, text: (shown.append(text),
                                                                            status(op, context, text))
    before = mesh_state(torus.data)
    with bpy.context.temp_override(**override):
        bpy.ops.ed.undo_push(message="the torus")
    bpy.context.scene["marker"] = 1
    with bpy.context.temp_override(**override):
        bpy.ops.ed.undo_push(message="marked")
    yield 0.2
    # 1: Esc while the worker prepares the mesh
    cache.prepared_meshes.clear()
    reached, release, restore = gate_preparation(background)
    try:
        with bpy.context.temp_override(**override):
            started = bpy.ops.topstoc.guided_decimate("INVOKE_DEFAULT")
        check("invoke returns while the worker runs", started == {"RUNNING_MODAL"})
        for _ in range(200):  # the worker begins at the modal's first event
            yield 0.05
            if reached.is_set():
                break
        check("the worker reached the preparation", reached.is_set())
        yield 0.5  # the modal's timer shows the progress meanwhile
        check("nothing written while it runs", sorted(bpy.data.objects.keys()) == ["Torus"])
        check("the header shows the preparation and how to cancel", any(
            "'Torus'" in text and "preparing" in text and "Esc: cancel" in text for text in shown if text), shown[-3:])
        window.event_simulate(type="ESC", value="PRESS")
        window.event_simulate(type="ESC", value="RELEASE")
        yield 0.3
    finally:
        release.set()
        restore()
    for _ in range(100):
        yield 0.05
        if not any(t.name == background.THREAD_NAME for t in threading.enumerate()):
            break
    check("the header is cleared after Esc", shown[-1] is None)
    check("Esc stopped the worker", not any(t.name == background.THREAD_NAME for t in threading.enumerate()))
    yield 0.5
    check("Esc leaves the object as it was", sorted(bpy.data.objects.keys()) == ["Torus"]
          and mesh_state(bpy.data.objects["Torus"].data) == before)
    check("nothing was cached from the stopped preparation", not cache.prepared_meshes._entries)
    with bpy.context.temp_override(**override):
        bpy.ops.ed.undo()
    yield 0.3
    check("Esc added no undo step (one undo goes back before the marker)", "marker" not in bpy.context.scene)
    # 2: a run to the end
    torus = bpy.data.objects["Torus"]
    torus.select_set(True)
    bpy.context.view_layer.objects.active = torus
    with bpy.context.temp_override(**override):
        bpy.ops.ed.undo_push(message="before the run")
        started = bpy.ops.topstoc.guided_decimate("INVOKE_DEFAULT")
    check("the second run is modal too", started == {"RUNNING_MODAL"})
    for _ in range(400):
        yield 0.05
        if "Torus_TopStoc" in bpy.data.objects:
            break
    yield 0.2
    out = bpy.data.objects.get("Torus_TopStoc")
    check("the modal run writes its result", out is not None)
    if out is None:
        return
    modal = mesh_state(out.data)
    check("the result is selected and active", bpy.context.view_layer.objects.active == out and out.select_get())
    with bpy.context.temp_override(**override):
        bpy.ops.ed.undo()
    yield 0.3
    check("one undo removes the modal run's result", "Torus_TopStoc" not in bpy.data.objects
          and mesh_state(bpy.data.objects["Torus"].data) == before)
    torus = bpy.data.objects["Torus"]
    torus.select_set(True)
    bpy.context.view_layer.objects.active = torus
    with bpy.context.temp_override(**override):
        done = bpy.ops.topstoc.guided_decimate("EXEC_DEFAULT")
    direct = bpy.data.objects.get("Torus_TopStoc")
    check("the immediate run writes the same mesh", done == {"FINISHED"} and direct is not None
          and mesh_state(direct.data) == modal and len(modal[0]) < len(before[0]) // 5,
          f"{len(modal[0])} vertices against {len(before[0])}")
    # 3: the worker's run, then Bake Normals stepped by the same modal handler
    bpy.data.objects.remove(direct)
    torus = bpy.data.objects["Torus"]
    torus.select_set(True)
    bpy.context.view_layer.objects.active = torus
    settings = bpy.context.scene.topstoc  # the undo steps above gave the scene new data
    settings.bake_normals, settings.bake_size = True, "256"
    with bpy.context.temp_override(**override):
        started = bpy.ops.topstoc.guided_decimate("INVOKE_DEFAULT")
    check("the run with Bake Normals is modal", started == {"RUNNING_MODAL"})
    for _ in range(1200):
        yield 0.05
        out = bpy.data.objects.get("Torus_TopStoc")
        if out is not None and normal_map_image(out) is not None and shown[-1] is None:
            break
    out = bpy.data.objects.get("Torus_TopStoc")
    check("the bake after the worker's run hooks a normal map into the result",
          out is not None and normal_map_image(out) is not None and mesh_state(out.data) == modal,
          f"{sorted(bpy.data.objects.keys())}, map {out and normal_map_image(out)}")
    check("the header is cleared after the bake", shown[-1] is None, shown[-3:])


try:
    addon_utils.enable("topstoc", default_set=True)
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    bpy.ops.mesh.primitive_torus_add(major_segments=96, minor_segments=48)
    decimate = sys.modules["topstoc.blender.operators.decimate"]
    background = sys.modules["topstoc.blender.decimation.background"]
    cache = sys.modules["topstoc.blender.preview.cache"]
    checks.drive(steps())
except Exception:
    traceback.print_exc()
    os._exit(1)
