"""Run by test_artist_gui.py in a windowed Blender under Xvfb: the decimation panel at the
default sidebar width (labels measured against their column, no red field), the Live Preview
with its wireframe, and the Topology panel's plain-words help. Screenshots + report.json."""

import os
import sys
import threading
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import session  # noqa: E402
from session import check, report, shot, view3d  # noqa: E402

ADDON = session.enable_addon()


def sidebar_rect():
    _window, area, _region, _space = view3d()
    sidebar = next(r for r in area.regions if r.type == "UI")
    return [sidebar.x, sidebar.y, sidebar.x + sidebar.width, sidebar.y + sidebar.height], sidebar


def label_fits(texts, sidebar):
    """The widest label against the label column of a property-split layout (40 % of the panel
    width less the margins), measured with Blender's UI font. Returns (widest text, its width,
    the column width)."""
    import blf

    scale = bpy.context.preferences.system.ui_scale or 1.0
    styles = bpy.context.preferences.ui_styles[0]
    style = getattr(styles, "widget_label", None) or styles.widget  # widget_label is gone in 4.x
    try:
        blf.size(0, style.points * scale)
    except TypeError:  # Blender before 4.0 takes a dpi argument
        blf.size(0, int(style.points * scale), 72)
    widest = max(texts, key=lambda t: blf.dimensions(0, t)[0])
    margin = 2 * 10 * scale + 20 * scale  # panel margins and the split's padding (Blender's ui_layout)
    # less the label's own text margins: 66 px of "Appearance" against 75 px was drawn cut
    column = 0.4 * (sidebar.width - margin) - 10 * scale
    return widest, blf.dimensions(0, widest)[0], column


def open_advanced():
    """Shows the Advanced sub-panel open (Blender 3.4 has no API to open a panel): registers the
    decimation sub-panels again, in their order, with Advanced no longer closed by default."""
    names = ("TOPSTOC_PT_advanced", "TOPSTOC_PT_guidance", "TOPSTOC_PT_variants", "TOPSTOC_PT_samples")
    classes = [getattr(bpy.types, name) for name in names]
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
    classes[0].bl_options = set()
    for cls in classes:
        bpy.utils.register_class(cls)


def steps():
    open_advanced()
    obj = bpy.data.objects["Suzanne"]
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    session.frame([obj], tilt=0.2, turn=0.0, distance_factor=2.2)
    yield from session.show_topstoc_tab()
    yield 0.5
    rect, sidebar = sidebar_rect()
    report["regions"]["sidebar"] = rect
    report["values"]["sidebar_width"] = sidebar.width
    shot("artist_panel", [obj])
    session.keep_for_docs("artist_panel", "artist-panel.png")
    settings = bpy.context.scene.topstoc
    labels = []
    # (Appearance is a full-width slider with its name inside, not in the label column)
    for name in ("target_mode", "ratio", "seed", "adaptivity", "density", "placement", "refine"):
        labels.append(settings.bl_rna.properties[name].name)
    widest, width, column = label_fits(labels, sidebar)
    report["values"]["widest_label"] = [widest, width, column]
    check("labels fit their column", width <= column, f"{widest!r}: {width:.0f} px of {column:.0f} px")
    check("no guidance layer yet", obj.data.color_attributes.get(obj.topstoc.color_attribute) is None)

    # the Advanced sub-panel open: expand it by drawing it open (its header is a click away)
    bpy.context.scene.topstoc.ratio = 0.1
    window, area, region, _space = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        started = bpy.ops.topstoc.preview("INVOKE_DEFAULT")
    check("preview started", started == {"RUNNING_MODAL"})
    yield 1.5
    begun = time.perf_counter()
    while "Suzanne_TopStocPreview" not in bpy.data.objects and time.perf_counter() - begun < 10:
        yield 0.1  # the worker begins at the modal's first event (PreviewSession.begin)
    preview = bpy.data.objects.get("Suzanne_TopStocPreview")
    check("preview object with wireframe", preview is not None and preview.show_wire)
    shot("preview_wire", [preview])
    session.keep_for_docs("preview_wire", "preview-wireframe.png")
    preview.show_wire = False
    area.tag_redraw()
    yield 0.5
    shot("preview_nowire", [preview])
    preview.show_wire = True
    window.event_simulate(type="ESC", value="PRESS")
    window.event_simulate(type="ESC", value="RELEASE")
    yield 0.5
    check("preview closed", "Suzanne_TopStocPreview" not in bpy.data.objects)

    with session.override():
        assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    yield from session.collapse_first_panel()
    yield 0.5
    shot("topology_help", [obj])
    session.keep_for_docs("topology_help", "topology-help.png")
    explain = bpy.types.TOPSTOC_OT_explain
    props = type("P", (), {"topic": "genus"})()
    report["values"]["genus_tooltip"] = explain.description(bpy.context, props)

    # a keymap's or script's explicit property wins over the panel on invoke; the rest comes
    # from the panel (background Blender cannot check this: it runs exec without a window)
    settings.output, settings.ratio = "NEW_OBJECT", 0.5
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    n = len(obj.data.vertices)
    names = set(bpy.data.objects.keys())
    with session.override():
        done = bpy.ops.topstoc.guided_decimate("INVOKE_DEFAULT", output="IN_PLACE")
    yield 0.3
    check("explicit output wins on invoke", done == {"FINISHED"} and set(bpy.data.objects.keys()) == names)
    check("unset ratio comes from the panel", abs(len(obj.data.vertices) - 0.5 * n) <= 0.02 * n,
          f"{len(obj.data.vertices)} of {n}")


    # a big mesh: the preview starts at once, says it is preparing, and Esc cancels it cleanly
    yield from big_mesh_preview(obj)


def big_mesh_preview(source):

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    import meshgen
    from topstoc.blender.io import mesh_write
    from topstoc.core.api.io import read_mesh

    data = read_mesh(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "open_boundary",
                                  "kivy_suzanne_monkey.obj"))
    vertices, triangles = meshgen.subdivide(data.vertices, data.triangles, 4)  # 1.0M triangles
    mesh = bpy.data.meshes.new("Big")
    mesh_write.fill_geometry(mesh, vertices, triangles)
    big = bpy.data.objects.new("Big", mesh)
    # Xvfb's software rasteriser takes seconds to draw a million triangles (a GPU milliseconds),
    # and the event loop waits for each frame: drawn as its bounds, Esc reaches the modal in time
    big.display_type = "BOUNDS"
    bpy.context.scene.collection.objects.link(big)
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    big.select_set(True)
    bpy.context.view_layer.objects.active = big
    source.hide_set(True)
    settings = bpy.context.scene.topstoc
    settings.target_mode, settings.ratio = "VERTICES", 0.3
    report["values"]["big_triangles"] = int(len(triangles))
    window, area, region, _space = view3d()
    sessions = sys.modules[ADDON.__name__ + ".blender.preview.session"]
    operators = sys.modules[ADDON.__name__ + ".blender.operators.preview"]
    created = []
    original_init = sessions.PreviewSession.__init__

    def remember(self, *args, **kwargs):
        original_init(self, *args, **kwargs)
        created.append(self)

    # Under Xvfb's software rasteriser on a loaded machine a frame can take a second, longer than
    # the preparation: the engine is held at its adjacency step (a gate in the progress callback)
    # until Esc has been handled, so that Esc surely comes while it prepares
    gate, held = threading.Event(), []
    report_progress = sessions.PreviewSession._report

    def gated(preview_session, fraction, stage):
        report_progress(preview_session, fraction, stage)
        if stage == "adjacency" and not held:
            held.append(stage)
            gate.wait(30)
        return report_progress(preview_session, fraction, stage)  # asked again after the wait

    yield 0.5  # the new mesh settles (drawn once) before the artist starts the preview
    sessions.PreviewSession.__init__ = remember
    sessions.PreviewSession._report = gated
    try:
        # 1: invoke returns while the mesh is still being prepared; Esc stops the engine
        clock, cpu = time.perf_counter(), time.thread_time()
        with session.override():
            started = bpy.ops.topstoc.preview("INVOKE_DEFAULT")
        report["values"]["big_invoke_seconds"] = time.perf_counter() - clock
        report["values"]["big_invoke_cpu_seconds"] = time.thread_time() - cpu
        first = created[-1] if created else None
        check("big preview starts at once", started == {"RUNNING_MODAL"} and first is not None and first.preparing,
              f"{report['values']['big_invoke_seconds']:.3f} s, {report['values']['big_invoke_cpu_seconds']:.3f} s CPU")
        yield 0.05
        begun = time.perf_counter()
        while first is not None and first.start is None and time.perf_counter() - begun < 10:
            yield 0.02  # the worker begins at the modal's first event (PreviewSession.begin)
        was_preparing = first.preparing
        window.event_simulate(type="ESC", value="PRESS")
        window.event_simulate(type="ESC", value="RELEASE")
        while operators.running:
            yield 0.02
        gate.set()
        escaped = time.perf_counter()
        while not first.start.done() and time.perf_counter() - escaped < 10:
            yield 0.02
        report["values"]["big_cancel_seconds"] = time.perf_counter() - escaped
        error = first.start.exception() if first.start.done() else None
        check("Esc stops the preparation in the engine", was_preparing and sessions.cancelled(error),
              f"{report['values']['big_cancel_seconds']:.3f} s: {error!r}")
        yield 0.3
        check("Esc cancels the big preview", "Big_TopStocPreview" not in bpy.data.objects and not big.hide_get()
              and len(big.data.polygons) == len(triangles))
        check("no preview thread or modal timer left", not operators.running
              and not any(t.name.startswith(sessions.THREAD_PREFIX) for t in threading.enumerate()))
        # 2: the header while preparing (a screenshot), then Esc
        with session.override():
            bpy.ops.topstoc.preview("INVOKE_DEFAULT")
        yield 0.01
        report["values"]["big_still_preparing_at_shot"] = created[-1].preparing
        shot("preview_preparing", [big])
        window.event_simulate(type="ESC", value="PRESS")
        window.event_simulate(type="ESC", value="RELEASE")
        yield 0.5
    finally:
        gate.set()
        sessions.PreviewSession.__init__ = original_init
        sessions.PreviewSession._report = report_progress
    check("the panel's target is back", settings.target_mode == "VERTICES" and abs(settings.ratio - 0.3) < 1e-6)


session.run(steps)
