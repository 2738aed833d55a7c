"""Modal live preview: drag the mouse to change the ratio, Enter applies, Esc restores.

Starting is immediate: invoke reads the mesh and its guidance (the only main-thread work) and
returns; the preview session fingerprints, prepares (when the mesh is not cached) and decimates
on a worker thread while the header and status bar show the preparation's progress with a wait
cursor. Esc cancels then too, and the engine stops preparing (not only the waiting); the object
is left as it was. The preview shows the Fast result with its wireframe while dragging and the
chosen Quality when the drag rests (throughout, where the chosen Quality is fast enough). The sidebar's ratio follows the drag (and goes back on
cancel).

Enter (or a click) applies the dragged ratio at the panel's settings. When the result on screen
is that result (the chosen Quality after the drag rested there) it is written as it is. Otherwise
the preview's worker computes it while the header and status bar count the seconds and the
cursor waits; the modal keeps running until it is ready (Esc cancels: nothing is written), then
writes it. Where moved vertices take their attributes from is found on a worker too, as soon as
a Quality result is computed. Either way the source changes only when the operator finishes, in
one undo step.
"""

from __future__ import annotations

import math
import time
from types import SimpleNamespace

import bpy

from ..decimation import pipeline
from ...core.support.errors import TopStocError
from ..decimation.guidance import GuidanceError
from ..preview.session import PreviewSession, cancelled
from ..props import OperatorParameters, fill_from_scene, settings_names
from . import polls
from .decimate import select_results

PIXELS_PER_DOUBLING = 150.0  # mouse travel that doubles (or halves) the ratio
#: Live previews whose modal timer is running (tests check that none is left behind).
running: set = set()


def shown_status(session, quality: str) -> str:
    """The header's words on the result shown: its counts, times and kind. A draft whose full
    decimation collapses it further (stats.collapses_skipped: above its target, or zero-area
    triangles left) says so: the rest shows fewer vertices."""
    result = session.result
    if session.final:
        kind = quality.title()
    elif result.stats.collapses_skipped:
        above = ", above target" if result.num_vertices > result.stats.target_vertices else ""
        kind = f"Fast draft while dragging{above}: the rested result collapses further"
    else:
        kind = "Fast draft while dragging"
    return (f"TopStoc ratio {session.ratio:.4f}: {result.num_vertices:,} vertices, {result.num_triangles:,} "
            f"triangles ({1000 * session.seconds_decimate:.0f} ms + {1000 * session.seconds_write:.0f} ms)  ({kind})")


class TOPSTOC_OT_preview(OperatorParameters, bpy.types.Operator):
    """Live preview: move the mouse left/right to change the ratio (wheel: fine steps); \
Enter or click applies, Esc or right-click restores"""

    bl_idname = "topstoc.preview"
    bl_label = "Live Preview"
    bl_options = {"REGISTER", "UNDO", "BLOCKING"}

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.active_mesh_in_object_mode(context) or polls.view_3d(context))

    def invoke(self, context, event):
        fill_from_scene(self, context.scene.topstoc)
        obj = context.object
        self.saved_scene = (context.scene.topstoc.target_mode, context.scene.topstoc.ratio)
        self.started = time.perf_counter()
        settings = SimpleNamespace(**{name: getattr(self, name) for name in settings_names()})
        try:  # reads the mesh and guidance; preparing and decimating go on in a worker
            self.session = PreviewSession(context, obj, settings, context.region_data, ratio=self.ratio,
                                          deferred=True)  # begun by the first modal event (begin)
        except (pipeline.DecimationError, GuidanceError, ValueError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.obj_name = obj.name
        self.start_x = event.mouse_x
        self.start_ratio = self.ratio
        self.min_ratio = 1.0 / max(1, len(obj.data.vertices))  # refined once the mesh is prepared
        self.timer = context.window_manager.event_timer_add(1.0 / 60.0, window=context.window)
        running.add(self.timer)
        context.window_manager.modal_handler_add(self)
        context.window.cursor_modal_set("WAIT")  # until the first result shows
        self.waiting = True
        self._header(context)
        return {"RUNNING_MODAL"}

    # -- feedback -----------------------------------------------------------------------------

    def _status(self, context, text):
        context.area.header_text_set(text)
        context.workspace.status_text_set(text)

    def _header(self, context):
        s = self.session
        result = s.result
        seconds = time.perf_counter() - self.started
        if s.applying:
            waited = time.perf_counter() - s.apply_started
            if s.apply_computed:
                doing = "interpolating the attributes of moved vertices"
            else:
                estimate = f" of about {s.final_seconds:.1f} s" if s.final_seconds else ""
                doing = f"computing the {self.quality.title()} result{estimate}"
            self._status(context, f"TopStoc: applying ratio {self.ratio:.4f}: {doing} ... {waited:.1f} s   Esc: cancel")
            return
        if s.preparing:
            fraction, stage = s.progress()
            self._status(context, f"TopStoc: preparing '{self.obj_name}' ({s.num_triangles:,} triangles): "
                                  f"{100 * fraction:.0f} % ({stage})  {seconds:.1f} s   Esc: cancel")
            return
        if result is None:
            self._status(context, f"TopStoc: decimating '{self.obj_name}' at ratio {self.ratio:.4f} ... "
                                  f"{seconds:.1f} s   Esc: cancel")
            return
        self._status(context, f"{shown_status(s, self.quality)}   "
                              "drag: ratio  wheel: fine  Enter/click: apply  Esc/right-click: cancel")

    def _follow(self, context):
        """The sidebar shows the ratio being dragged."""
        settings = context.scene.topstoc
        if settings.target_mode != "RATIO" or abs(settings.ratio - self.ratio) > 1e-9:
            settings.target_mode, settings.ratio = "RATIO", self.ratio
        for region in context.area.regions:
            if region.type == "UI":
                region.tag_redraw()

    def _finish(self, context, restore_scene: bool = False):
        context.window_manager.event_timer_remove(self.timer)
        running.discard(self.timer)
        context.area.header_text_set(None)
        context.workspace.status_text_set(None)
        context.window.cursor_modal_restore()
        self.session.close()  # cancels a preparation still running
        if restore_scene:
            context.scene.topstoc.target_mode, context.scene.topstoc.ratio = self.saved_scene

    def _fail(self, context, error):
        self._finish(context, restore_scene=True)
        self.report({"ERROR"}, str(error))
        return {"CANCELLED"}

    # -- the drag -----------------------------------------------------------------------------

    def _set_ratio(self, context, ratio):
        self.ratio = min(1.0, max(self.min_ratio, ratio))
        self.session.request(self.ratio)
        self._follow(context)

    def modal(self, context, event):
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            self._finish(context, restore_scene=True)
            return {"CANCELLED"}
        self.session.begin()  # after invoke has returned to Blender (see PreviewSession.begin)
        if self.session.applying:  # the drag is over: only the result to apply is awaited
            return self._poll_apply(context) if event.type == "TIMER" else {"RUNNING_MODAL"}
        if event.type == "MOUSEMOVE":
            exponent = (event.mouse_x - self.start_x) / PIXELS_PER_DOUBLING
            self._set_ratio(context, self.start_ratio * math.pow(2.0, exponent))
        elif event.type in {"WHEELUPMOUSE", "WHEELDOWNMOUSE"}:
            factor = 1.05 if event.type == "WHEELUPMOUSE" else 1 / 1.05
            self.start_ratio = min(1.0, max(self.min_ratio, self.start_ratio * factor))
            self._set_ratio(context, self.ratio * factor)
        elif event.type == "TIMER":
            was_preparing = self.session.preparing
            try:
                shown = self.session.poll()
            except (ValueError, RuntimeError) as error:  # a failed preparation or decimation
                if cancelled(error):
                    return {"RUNNING_MODAL"}
                return self._fail(context, error)
            if was_preparing and not self.session.preparing and self.session.prepared is not None:
                active = self.session.prepared.mesh.report()
                self.min_ratio = 1.0 / max(1, active.input_vertices - active.isolated_vertices)
            if shown and self.waiting:
                context.window.cursor_modal_restore()
                self.waiting = False
            if shown or self.session.result is None:
                self._header(context)
        elif event.type in {"RET", "NUMPAD_ENTER", "LEFTMOUSE"} and event.value == "PRESS":
            if self.session.result is None:
                return {"RUNNING_MODAL"}  # nothing shown yet to apply
            self.target_mode = "RATIO"
            self._follow(context)
            run = self.session.apply(self.ratio)  # the result shown, when it is the one to apply
            if run is not None:
                return self._apply(context, run)
            context.window.cursor_modal_set("WAIT")
            self._header(context)
        return {"RUNNING_MODAL"}

    # -- applying -----------------------------------------------------------------------------

    def _poll_apply(self, context):
        try:
            run = self.session.poll_apply()
        except (ValueError, RuntimeError) as error:  # the final decimation failed
            return self._fail(context, error)
        if run is None:
            self._header(context)
            return {"RUNNING_MODAL"}
        return self._apply(context, run)

    def _apply(self, context, run):
        """Writes the result (main thread); the preview goes first, so the source is shown again."""
        start = time.perf_counter()
        self._finish(context)
        try:
            if self.output == "NEW_OBJECT":
                pipeline.store_samples(run)
            select_results(context, [pipeline.write_output(run, self.output)])  # Guided Decimate stays usable
        except TopStocError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"TopStoc: {pipeline.summary(run, run.seconds + time.perf_counter() - start)}")
        return {"FINISHED"}


CLASSES = (TOPSTOC_OT_preview,)
