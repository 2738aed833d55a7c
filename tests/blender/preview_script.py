"""Run by test_preview_modal.py in a windowed Blender under Xvfb with --enable-event-simulate:
drives the Live Preview modal with simulated mouse and keyboard events. Prints one line per
check and exits 0 only when all hold."""

import os
import sys
import threading
import traceback

import addon_utils
import bpy

sys.path.insert(0, os.environ["TOPSTOC_BUILD_PYTHON"])
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from windowed_steps import Checks, view3d  # noqa: E402

checks = Checks("preview")
check = checks.check


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
    # The worker begins at the modal's first event (PreviewSession.begin), which a loaded
    # machine under Xvfb delivers late: wait for the result up to 10 s.
    waited = 0.0
    while "Torus_TopStocPreview" not in bpy.data.objects and waited < 10:
        yield 0.1
        waited += 0.1
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
    for _ in range(100):  # the Quality result may still be on its way (a loaded machine)
        yield 0.1
        if not operators.running:
            break
    out = bpy.data.objects.get("Torus_TopStoc")
    check("Enter applies", out is not None and abs(len(out.data.vertices) - 0.2 * n) <= 0.01 * n)
    check("preview removed", "Torus_TopStocPreview" not in bpy.data.objects
          and not bpy.data.objects["Torus"].hide_get())
    check("ratio stored in the panel", abs(bpy.context.scene.topstoc.ratio - 0.2) < 0.005)
    check("no modal timer left after Enter", not operators.running)
    selected = [o.name for o in bpy.context.view_layer.objects if o.select_get()]
    check("the result selected and active after Enter (Guided Decimate usable)", out is not None
          and selected == [out.name] and bpy.context.view_layer.objects.active == out, str(selected))
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
        waited = 0.0
        while not held and waited < 10:  # the worker begins at the modal's first event
            yield 0.1
            waited += 0.1
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
    yield from apply_steps(window, area, region, cx, cy)


class EngineCalls:
    """Wraps the pipeline's run_engine (every preview computation goes through it): counts the
    calls and holds quality ones while ``gate`` is closed."""

    def __init__(self, pipeline):
        self.pipeline, self.original = pipeline, pipeline.run_engine
        self.calls, self.gate, self.held = [], threading.Event(), threading.Event()
        self.gate.set()

        def run_engine(mesh, job, progress=None, cancel=None):
            self.calls.append((job.mode, job.target, threading.current_thread().name))
            if job.mode == "quality" and not self.gate.is_set():
                self.held.set()
                self.gate.wait(30)
            return self.original(mesh, job, progress, cancel)

        pipeline.run_engine = run_engine

    def restore(self):
        self.gate.set()
        self.pipeline.run_engine = self.original


def mesh_arrays(mesh):
    co = [tuple(v.co) for v in mesh.vertices]
    return co, [tuple(p.vertices) for p in mesh.polygons]


def apply_steps(window, area, region, cx, cy):
    """Enter applies the result on screen when it has the settings applied (no second
    decimation), otherwise computes it on the worker while the modal keeps running; Esc then
    cancels; undo takes the source back in one step."""
    settings = bpy.context.scene.topstoc
    for obj in list(bpy.data.objects):
        if obj.name.startswith("Torus_TopStoc"):
            bpy.data.objects.remove(obj)
    torus = bpy.data.objects["Torus"]
    n = len(torus.data.vertices)
    created = []
    original_init = sessions.PreviewSession.__init__

    def remember(self, *args, **kwargs):
        original_init(self, *args, **kwargs)
        created.append(self)

    def start(ratio):
        torus.select_set(True)
        bpy.context.view_layer.objects.active = torus
        settings.target_mode, settings.ratio = "RATIO", ratio
        window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=cx, y=cy)
        yield 0.2  # the move is handled before the preview starts (it starts where the mouse is)
        with bpy.context.temp_override(window=window, area=area, region=region):
            started = bpy.ops.topstoc.preview("INVOKE_DEFAULT")
        if started != {"RUNNING_MODAL"}:
            raise RuntimeError(f"the preview did not start: {started}")

    def press(key):
        window.event_simulate(type=key, value="PRESS")
        window.event_simulate(type=key, value="RELEASE")

    engine = EngineCalls(sessions.pipeline)
    sessions.PreviewSession.__init__ = remember
    settings.quality, settings.output, settings.seed = "QUALITY", "NEW_OBJECT", 4
    try:
        # 6: the drag rests: the Quality result shows; Enter writes exactly that mesh, no new decimation
        yield from start(0.1)
        for _ in range(200):
            yield 0.05
            if created and created[-1].final:
                break
        session = created[-1]
        shown = mesh_arrays(session.mesh) if session.final else None
        calls = len(engine.calls)
        press("RET")
        for _ in range(200):
            yield 0.05
            if not operators.running:
                break
        out = bpy.data.objects.get("Torus_TopStoc")
        check("a rested quality result shows", shown is not None and [c[0] for c in engine.calls] == ["fast", "quality"])
        check("Enter writes the mesh shown", out is not None and mesh_arrays(out.data) == shown)
        check("... without a second decimation", len(engine.calls) == calls and not operators.running)
        reference = sessions.pipeline.decimate(bpy.context, torus, settings).result
        check("... which is the Quality result", out is not None and len(out.data.vertices) == reference.num_vertices
              and [tuple(map(float, v)) for v in reference.vertices.astype("float32")] == mesh_arrays(out.data)[0])
        bpy.data.objects.remove(out)

        # 7: Enter during the drag: the Quality result at the dragged ratio is computed on the worker
        # (drafts while dragging and no rest, which a loaded machine may take between the events:
        # test_preview_rest.py tests those)
        rest, direct, speculate = sessions.REST_SECONDS, sessions.DIRECT_SECONDS, sessions.SPECULATE
        sessions.REST_SECONDS, sessions.DIRECT_SECONDS, sessions.SPECULATE = 86400.0, 0.0, False
        engine.calls.clear()
        yield from start(0.1)
        for _ in range(200):
            yield 0.05
            if created[-1].result is not None:
                break
        engine.gate.clear()
        window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=cx + 75, y=cy)
        press("RET")
        session = created[-1]
        # simulated events are handled when the window's event loop comes round (late under load)
        for _ in range(200):
            yield 0.05
            if engine.held.is_set() or not operators.running:
                break
        check("Enter during the drag keeps the modal running while the worker computes",
              operators.running and session.applying and engine.held.is_set()
              and "Torus_TopStoc" not in bpy.data.objects)
        final = [c for c in engine.calls if c[0] == "quality"]
        check("... the chosen Quality at the dragged ratio, on the worker", len(final) == 1
              and abs(final[0][1].ratio - 0.1 * 2 ** 0.5) < 0.002
              and final[0][2].startswith(sessions.THREAD_PREFIX), str(final))
        engine.gate.set()
        for _ in range(200):
            yield 0.05
            if not operators.running:
                break
        out = bpy.data.objects.get("Torus_TopStoc")
        reference = sessions.pipeline.decimate(bpy.context, torus, settings).result
        check("... then writes it", out is not None and abs(settings.ratio - final[0][1].ratio) < 1e-6
              and [tuple(map(float, v)) for v in reference.vertices.astype("float32")] == mesh_arrays(out.data)[0])
        check("... and leaves no preview, thread or timer", "Torus_TopStocPreview" not in bpy.data.objects
              and not torus.hide_get() and not operators.running
              and not any(t.name.startswith(sessions.THREAD_PREFIX) for t in threading.enumerate()))
        bpy.data.objects.remove(out)
        sessions.REST_SECONDS, sessions.DIRECT_SECONDS, sessions.SPECULATE = rest, direct, speculate

        # 8: Esc while the result to apply is computed: nothing written, the source as it was
        before = mesh_arrays(torus.data)
        names = sorted(bpy.data.objects.keys())
        yield from start(0.1)
        for _ in range(200):
            yield 0.05
            if created[-1].result is not None:
                break
        engine.held.clear()
        engine.gate.clear()
        window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=cx + 40, y=cy)
        press("RET")
        for _ in range(200):
            yield 0.05
            if engine.held.is_set() or not operators.running:
                break
        applying = created[-1].applying and engine.held.is_set()
        press("ESC")
        for _ in range(200):
            yield 0.05
            if not operators.running:
                break
        check("Esc during the final computation cancels", applying and not operators.running
              and sorted(bpy.data.objects.keys()) == names and not torus.hide_get()
              and mesh_arrays(torus.data) == before,
              f"applying {applying}, running {bool(operators.running)}, objects {sorted(bpy.data.objects.keys())} "
              f"(before {names}), hidden {torus.hide_get()}, unchanged {mesh_arrays(torus.data) == before}")
        engine.gate.set()
        for _ in range(200):
            yield 0.05
            if not any(t.name.startswith(sessions.THREAD_PREFIX) for t in threading.enumerate()):
                break
        yield 0.3
        check("... the computation ends unseen: no thread, timer or object left",
              not any(t.name.startswith(sessions.THREAD_PREFIX) for t in threading.enumerate())
              and not operators.running and sorted(bpy.data.objects.keys()) == names
              and abs(settings.ratio - 0.1) < 1e-6)

        # 9: In Place, then one undo: the source is back
        settings.output = "IN_PLACE"
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.ed.undo_push(message="before the preview")
        yield from start(0.1)
        for _ in range(200):
            yield 0.05
            if created[-1].final:
                break
        press("RET")
        for _ in range(200):
            yield 0.05
            if not operators.running:
                break
        applied = len(bpy.data.objects["Torus"].data.vertices)
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.ed.undo()
        yield 0.3
        torus = bpy.data.objects["Torus"]
        check("In Place applies, one undo restores the source", applied < 0.2 * n
              and mesh_arrays(torus.data) == before and "Torus_TopStocPreview" not in bpy.data.objects,
              f"{applied} of {n}")
    finally:
        engine.restore()
        sessions.PreviewSession.__init__ = original_init


try:
    addon_utils.enable("topstoc", default_set=True)
    bpy.ops.mesh.primitive_torus_add(major_segments=96, minor_segments=48)
    sessions = sys.modules["topstoc.blender.preview.session"]
    sessions.prepared_meshes_clear = sys.modules["topstoc.blender.preview.cache"].prepared_meshes.clear
    operators = sys.modules["topstoc.blender.operators.preview"]
    checks.drive(steps())
except Exception:
    traceback.print_exc()
    os._exit(1)
