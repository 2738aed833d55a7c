"""Modal live preview: drag the mouse to change the ratio, Enter applies, Esc restores."""

from __future__ import annotations

import math

import bpy

from .. import pipeline
from ...core.errors import TopStocError
from ..preview import PreviewSession
from ..props import DecimationParameters, copy_parameters

PIXELS_PER_DOUBLING = 150.0  # mouse travel that doubles (or halves) the ratio


class TOPSTOC_OT_preview(DecimationParameters, bpy.types.Operator):
    """Live preview: move the mouse left/right to change the ratio (wheel: fine steps); \
Enter or click applies, Esc or right-click restores"""

    bl_idname = "topstoc.preview"
    bl_label = "Live Preview"
    bl_options = {"REGISTER", "UNDO", "BLOCKING"}

    @classmethod
    def poll(cls, context):
        obj = context.object
        return (context.mode == "OBJECT" and obj is not None and obj.type == "MESH"
                and context.area is not None and context.area.type == "VIEW_3D")

    def invoke(self, context, event):
        copy_parameters(context.scene.topstoc, self)
        obj = context.object
        try:
            self.session = PreviewSession(context, obj, self, context.region_data)
        except ValueError as error:  # TopStocError or an engine refusal
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.active = self.session.prepared.mesh.report()
        self.min_ratio = 1.0 / max(1, self.active.input_vertices - self.active.isolated_vertices)
        self.start_x = event.mouse_x
        self.start_ratio = self.ratio
        self.session.update(self.ratio)
        self.timer = context.window_manager.event_timer_add(1.0 / 60.0, window=context.window)
        context.window_manager.modal_handler_add(self)
        self._header(context)
        return {"RUNNING_MODAL"}

    def _header(self, context):
        s = self.session
        result = s.result
        context.area.header_text_set(
            f"TopStoc ratio {s.ratio:.4f}: {result.num_vertices:,} vertices, {result.num_triangles:,} triangles "
            f"({1000 * s.seconds_decimate:.0f} ms + {1000 * s.seconds_write:.0f} ms)   "
            "drag: ratio  wheel: fine  Enter/click: apply  Esc/right-click: cancel")

    def _finish(self, context):
        context.window_manager.event_timer_remove(self.timer)
        context.area.header_text_set(None)
        self.session.close()

    def modal(self, context, event):
        if event.type == "MOUSEMOVE":
            exponent = (event.mouse_x - self.start_x) / PIXELS_PER_DOUBLING
            self.ratio = min(1.0, max(self.min_ratio, self.start_ratio * math.pow(2.0, exponent)))
            self.session.request(self.ratio)
        elif event.type in {"WHEELUPMOUSE", "WHEELDOWNMOUSE"}:
            factor = 1.05 if event.type == "WHEELUPMOUSE" else 1 / 1.05
            self.start_ratio = min(1.0, max(self.min_ratio, self.start_ratio * factor))
            self.ratio = min(1.0, max(self.min_ratio, self.ratio * factor))
            self.session.request(self.ratio)
        elif event.type == "TIMER":
            try:
                if self.session.poll():
                    self._header(context)
            except ValueError as error:
                self._finish(context)
                self.report({"ERROR"}, str(error))
                return {"CANCELLED"}
        elif event.type in {"RET", "NUMPAD_ENTER", "LEFTMOUSE"} and event.value == "PRESS":
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
        elif event.type in {"ESC", "RIGHTMOUSE"} and event.value == "PRESS":
            self._finish(context)
            return {"CANCELLED"}
        return {"RUNNING_MODAL"}


CLASSES = (TOPSTOC_OT_preview,)
