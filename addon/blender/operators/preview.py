"""Modal live preview: drag the mouse to change the ratio, Enter applies, Esc restores.

Starting is immediate: the mesh is read on the main thread, and a mesh not prepared yet is
prepared on a worker thread (the engine releases the GIL) while the header and status bar show
what is happening with a wait cursor; Esc cancels then too. The preview always shows the Fast
result with its wireframe; Enter writes the result at the panel's Quality. The sidebar's ratio
follows the drag (and goes back on cancel).
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from types import SimpleNamespace

import bpy

from ...core.mesh import Mesh
from .. import mesh_io, pipeline
from ...core.errors import TopStocError
from ..cache import prepared_meshes
from ..guidance import GuidanceError
from ..preview import PreviewSession
from ..props import OperatorParameters, fill_from_scene, settings_names
from . import polls

PIXELS_PER_DOUBLING = 150.0  # mouse travel that doubles (or halves) the ratio
_preparer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="topstoc-prepare")


class TOPSTOC_OT_preview(OperatorParameters, bpy.types.Operator):
    """Live preview: move the mouse left/right to change the ratio (wheel: fine steps); \
Enter or click applies, Esc or right-click restores"""

    bl_idname = "topstoc.preview"
    bl_label = "Live Preview"
    bl_options = {"REGISTER", "UNDO", "BLOCKING"}

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.active_mesh_in_object_mode(context) or polls.view_3d(context))

    # -- starting: read, prepare off the main thread, then open the session ----------------

    def invoke(self, context, event):
        fill_from_scene(self, context.scene.topstoc)
        obj = context.object
        self.session = None
        self.saved_scene = (context.scene.topstoc.target_mode, context.scene.topstoc.ratio)
        self.start_x = event.mouse_x
        self.started = time.perf_counter()
        try:
            mesh_io.check_mesh_object(obj, pipeline.DecimationError)
            arrays, digest, entry = prepared_meshes.find(obj.data)
        except ValueError as error:  # TopStocError or an engine refusal
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.obj_name = obj.name
        self.preparing = None
        if entry is None:  # prepare on a worker: the window stays responsive and Esc works
            self.pending = (arrays, digest)
            self.preparing = _preparer.submit(Mesh, arrays.vertices, arrays.triangles)
        self.timer = context.window_manager.event_timer_add(1.0 / 60.0, window=context.window)
        context.window_manager.modal_handler_add(self)
        context.window.cursor_modal_set("WAIT")
        self._status(context, f"TopStoc: preparing '{obj.name}' ({len(arrays.triangles):,} triangles) ...")
        if self.preparing is None:
            return self._open(context, event)
        return {"RUNNING_MODAL"}

    def _open(self, context, event=None):
        """Preparation done: opens the preview session (guidance, preview object)."""
        obj = bpy.data.objects.get(self.obj_name)
        # The session shows Fast while the slider moves and the chosen quality when it rests.
        settings = SimpleNamespace(**{name: getattr(self, name) for name in settings_names()})
        try:
            self.session = PreviewSession(context, obj, settings, context.region_data)
        except (pipeline.DecimationError, GuidanceError, ValueError) as error:
            self._finish(context)
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        context.window.cursor_modal_restore()
        active = self.session.prepared.mesh.report()
        self.min_ratio = 1.0 / max(1, active.input_vertices - active.isolated_vertices)
        if event is not None:
            self.start_x = event.mouse_x
        self.start_ratio = self.ratio
        self.session.update(self.ratio)  # the first result at once (a prepared mesh decimates in ms)
        self._follow(context)
        self._header(context)
        return {"RUNNING_MODAL"}

    def _poll_preparation(self, context):
        if not self.preparing.done():
            seconds = time.perf_counter() - self.started
            self._status(context, f"TopStoc: preparing '{self.obj_name}' ... {seconds:.1f} s   Esc: cancel")
            return {"RUNNING_MODAL"}
        try:
            mesh = self.preparing.result()
        except ValueError as error:
            self._finish(context)
            self.report({"ERROR"}, f"'{self.obj_name}': {error}")
            return {"CANCELLED"}
        obj = bpy.data.objects.get(self.obj_name)
        prepared_meshes.add(obj.data, *self.pending, mesh)
        self.preparing = None
        return self._open(context)

    # -- feedback -----------------------------------------------------------------------------

    def _status(self, context, text):
        context.area.header_text_set(text)
        context.workspace.status_text_set(text)

    def _header(self, context):
        s = self.session
        result = s.result
        if result is None:
            seconds = time.perf_counter() - self.started
            self._status(context, f"TopStoc: decimating '{s.obj.name}' at ratio {self.ratio:.4f} ... "
                                  f"{seconds:.1f} s   Esc: cancel")
            return
        quality = "" if self.quality == "FAST" else \
            f"  ({self.quality.title() if s.final else 'Fast while dragging'})"
        self._status(context,
                     f"TopStoc ratio {s.ratio:.4f}: {result.num_vertices:,} vertices, {result.num_triangles:,} "
                     f"triangles ({1000 * s.seconds_decimate:.0f} ms + {1000 * s.seconds_write:.0f} ms){quality}   "
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
        context.area.header_text_set(None)
        context.workspace.status_text_set(None)
        context.window.cursor_modal_restore()
        if self.session is not None:
            self.session.close()
        if restore_scene:
            context.scene.topstoc.target_mode, context.scene.topstoc.ratio = self.saved_scene

    # -- the drag -----------------------------------------------------------------------------

    def modal(self, context, event):
        if event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            self._finish(context, restore_scene=True)  # a preparation still running is left to finish
            return {"CANCELLED"}
        if self.preparing is not None:
            if event.type == "TIMER":
                return self._poll_preparation(context)
            return {"RUNNING_MODAL"}
        if event.type == "MOUSEMOVE":
            exponent = (event.mouse_x - self.start_x) / PIXELS_PER_DOUBLING
            self.ratio = min(1.0, max(self.min_ratio, self.start_ratio * math.pow(2.0, exponent)))
            self.session.request(self.ratio)
            self._follow(context)
        elif event.type in {"WHEELUPMOUSE", "WHEELDOWNMOUSE"}:
            factor = 1.05 if event.type == "WHEELUPMOUSE" else 1 / 1.05
            self.start_ratio = min(1.0, max(self.min_ratio, self.start_ratio * factor))
            self.ratio = min(1.0, max(self.min_ratio, self.ratio * factor))
            self.session.request(self.ratio)
            self._follow(context)
        elif event.type == "TIMER":
            try:
                if self.session.poll() or self.session.result is None:
                    self._header(context)
            except ValueError as error:
                self._finish(context)
                self.report({"ERROR"}, str(error))
                return {"CANCELLED"}
        elif event.type in {"RET", "NUMPAD_ENTER", "LEFTMOUSE"} and event.value == "PRESS":
            if self.session.result is None:
                return {"RUNNING_MODAL"}  # nothing shown yet to apply
            obj, ratio = self.session.obj, self.session.ratio
            self._finish(context)
            self.target_mode, self.ratio = "RATIO", ratio
            context.scene.topstoc.target_mode, context.scene.topstoc.ratio = "RATIO", ratio
            try:
                run = pipeline.decimate(context, obj, self, region_3d=context.region_data)
                if self.output == "NEW_OBJECT":
                    pipeline.store_samples(run)
                pipeline.write_output(run, self.output)
            except TopStocError as error:
                self.report({"ERROR"}, str(error))
                return {"CANCELLED"}
            self.report({"INFO"}, f"TopStoc: {pipeline.summary(run)}")
            return {"FINISHED"}
        return {"RUNNING_MODAL"}


CLASSES = (TOPSTOC_OT_preview,)
