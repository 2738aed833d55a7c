"""Run by test_preview_modal.py in a windowed Blender under Xvfb with --enable-event-simulate:
drives the Live Preview modal with simulated mouse and keyboard events. Prints one line per
check and exits 0 only when all hold."""

import os
import sys
import traceback

import addon_utils
import bpy

sys.path.insert(0, os.environ["TOPSTOC_BUILD_PYTHON"])
failures = []
state = {}


def check(name, ok):
    print(f"preview check {name}: {'ok' if ok else 'FAILED'}", flush=True)
    if not ok:
        failures.append(name)


def finish():
    sys.stdout.flush()
    os._exit(1 if failures else 0)


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, area, region


def steps():
    window, area, region = view3d()
    cx, cy = region.x + region.width // 2, region.y + region.height // 2
    # 1: start the preview at ratio 0.1 with the mouse in the middle of the viewport
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=cx, y=cy)
    yield 0.2
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.context.scene.topstoc.ratio = 0.1
        result = bpy.ops.topstoc.preview("INVOKE_DEFAULT")
    check("modal started", result == {"RUNNING_MODAL"})
    yield 0.5
    preview = bpy.data.objects.get("Torus_TopStocPreview")
    check("preview object shown, original hidden", preview is not None and bpy.data.objects["Torus"].hide_get())
    n = len(bpy.data.objects["Torus"].data.vertices)
    check("preview at 10 %", preview is not None and abs(len(preview.data.vertices) - 0.1 * n) <= 0.01 * n)
    check("preview shows its wireframe", preview is not None and preview.show_wire and preview.show_all_edges)
    # 2: drag 150 px right: the ratio doubles; the preview follows
    for k in range(1, 11):
        window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=cx + 15 * k, y=cy)
        yield 0.05
    yield 1.5
    preview = bpy.data.objects.get("Torus_TopStocPreview")
    check("preview follows the drag to 20 %", preview is not None
          and abs(len(preview.data.vertices) - 0.2 * n) <= 0.01 * n)
    check("the sidebar ratio follows the drag", abs(bpy.context.scene.topstoc.ratio - 0.2) < 0.005)
    # 3: Enter applies: a new object at 20 %, the preview gone, the original visible again
    window.event_simulate(type="RET", value="PRESS")
    window.event_simulate(type="RET", value="RELEASE")
    yield 1.0
    out = bpy.data.objects.get("Torus_TopStoc")
    check("Enter applies", out is not None and abs(len(out.data.vertices) - 0.2 * n) <= 0.01 * n)
    check("preview removed", "Torus_TopStocPreview" not in bpy.data.objects
          and not bpy.data.objects["Torus"].hide_get())
    check("ratio stored in the panel", abs(bpy.context.scene.topstoc.ratio - 0.2) < 0.005)
    check("no modal timer left after Enter", not operators.running)
    # 4: a second preview cancelled with Esc leaves nothing behind
    bpy.data.objects["Torus_TopStoc"].select_set(False)
    bpy.context.view_layer.objects.active = bpy.data.objects["Torus"]
    bpy.data.objects["Torus"].select_set(True)
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.topstoc.preview("INVOKE_DEFAULT")
    yield 0.5
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=cx - 100, y=cy)
    yield 0.5
    window.event_simulate(type="ESC", value="PRESS")
    window.event_simulate(type="ESC", value="RELEASE")
    yield 0.5
    names = sorted(o.name for o in bpy.data.objects if o.type == "MESH")
    check("Esc restores", names == ["Cube", "Torus", "Torus_TopStoc"] and not bpy.data.objects["Torus"].hide_get())
    check("no modal timer left behind", not operators.running)
    # 5: Esc while the mesh is being prepared (the engine held at its adjacency step by a gate in
    # the progress callback): invoke has returned, nothing changed; Esc stops the engine there
    import threading

    torus = bpy.data.objects["Torus"]
    before = [tuple(v.co) for v in torus.data.vertices]
    sessions.prepared_meshes_clear()
    gate, held = threading.Event(), []
    report = sessions.PreviewSession._report

    def gated(session, fraction, stage):
        report(session, fraction, stage)
        if stage == "adjacency":
            held.append(session)
            gate.wait(30)
        return report(session, fraction, stage)

    sessions.PreviewSession._report = gated
    try:
        with bpy.context.temp_override(window=window, area=area, region=region):
            started = bpy.ops.topstoc.preview("INVOKE_DEFAULT")
        check("invoke returns while the mesh is prepared", started == {"RUNNING_MODAL"} and operators.running)
        yield 0.5
        check("preparing: nothing changed yet", bool(held) and held[0].preparing
              and "Torus_TopStocPreview" not in bpy.data.objects and not torus.hide_get())
        window.event_simulate(type="ESC", value="PRESS")
        window.event_simulate(type="ESC", value="RELEASE")
        yield 0.2
        gate.set()
        yield 1.0
    finally:
        gate.set()
        sessions.PreviewSession._report = report
    error = held[0].start.exception() if held and held[0].start.done() else None
    check("Esc stopped the preparation in the engine", sessions.cancelled(error)
          and not any(t.name.startswith("topstoc-preview") for t in threading.enumerate()))
    check("Esc during preparation leaves the object untouched", not operators.running
          and "Torus_TopStocPreview" not in bpy.data.objects and not torus.hide_get()
          and [tuple(v.co) for v in torus.data.vertices] == before)


def run():
    try:
        delay = next(state["steps"])
        return delay
    except StopIteration:
        finish()
    except Exception:
        traceback.print_exc()
        failures.append("exception")
        finish()


try:
    addon_utils.enable("topstoc", default_set=True)
    bpy.ops.mesh.primitive_torus_add(major_segments=96, minor_segments=48)
    sessions = sys.modules["topstoc.blender.preview"]
    sessions.prepared_meshes_clear = sys.modules["topstoc.blender.cache"].prepared_meshes.clear
    operators = sys.modules["topstoc.blender.operators.preview"]
    state["steps"] = steps()
    bpy.app.timers.register(run, first_interval=1.0)
except Exception:
    traceback.print_exc()
    os._exit(1)
