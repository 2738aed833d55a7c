"""The one-click "Guided Decimate" operator (object mode, every selected mesh).

Run from the interface on big meshes (BACKGROUND_TRIANGLES in all) or with a Max Deviation
target, it is modal: the meshes are read, then prepared and decimated on a worker thread while
the header, the status bar and the window's cursor show the progress and the window stays live;
Esc cancels (the engine stops at its next step) and leaves every object as it was, with no undo
step. The results are written on the main thread when all are done, in one undo step. The redo
panel and scripts run it at once (execute).
"""

from __future__ import annotations

import time

import bpy

from ..decimation import pipeline
from ..decimation.background import BackgroundDecimation
from ...core.support.errors import TopStocError
from ..props import OperatorBakeParameters, OperatorParameters, explicit_engine_options, fill_from_scene
from ..ui.panels import draw_bake
from . import bake_run, polls


def select_results(context, outputs) -> None:
    """The results selected and the first active, nothing else (the next step acts on them)."""
    for obj in context.selected_objects:
        obj.select_set(False)
    for obj in outputs:
        obj.select_set(True)
    context.view_layer.objects.active = outputs[0]


def selected_meshes(context):
    return [obj for obj in context.selected_objects if obj.type == "MESH"]


#: input triangles from which the run goes to a worker thread: quality mode collapses a mesh of
#: up to 250,000 vertices whole, a second or more from about 150,000 triangles
BACKGROUND_TRIANGLES = 150_000
#: events the window keeps while the run goes on (the view can be turned); others wait for it
NAVIGATION = {"MIDDLEMOUSE", "WHEELUPMOUSE", "WHEELDOWNMOUSE", "TRACKPADPAN", "TRACKPADZOOM", "MOUSEMOVE",
              "INBETWEEN_MOUSEMOVE", "MOUSEROTATE", "NDOF_MOTION"}


class Outcome:
    """What one run of the operator made: its outputs and the lines it reports (``missed``: a
    missed target or a topology not kept, one warning line each)."""

    def __init__(self, started: float):
        self.started = started
        self.outputs, self.lines, self.failures, self.sources, self.missed = [], [], [], [], []


def write_run(operator, run, done: Outcome) -> None:
    """Writes one object's result for Guided Decimate ``operator`` (main thread); a failed write
    raises TopStocError."""
    if operator.output == "NEW_OBJECT":
        pipeline.store_samples(run)
    done.outputs.append(pipeline.write_output(run, operator.output))
    done.sources.append(run.obj)
    done.lines.append(pipeline.summary(run))
    if run.result.stats.target_missed is not None:
        done.missed.append(f"{run.obj.name}: {run.result.stats.target_missed.text()}")
    if run.result.stats.topology_warning:
        done.missed.append(f"{run.obj.name}: {run.result.stats.topology_warning}")


def conclude(operator, context, done: Outcome):
    """Bakes when asked (modal where the window gets events: the operator's bake_finished then
    reports), else reports at once; selects the results (main thread, after every write)."""
    if operator.bake_normals and done.outputs:
        if operator.output != "NEW_OBJECT":
            done.failures.append("Bake Normals needs Output: New Object (in place, no original is left to "
                                 "bake from)")
        elif getattr(operator, "_modal", False):
            operator._done = done
            return operator.start_bake(context, list(zip(done.sources, done.outputs)), done.outputs)
        else:
            finished = bake_run.bake_or_discard(context, operator, zip(done.sources, done.outputs), done.outputs)
            if finished is None:
                operator.report({"WARNING"}, "TopStoc: Bake Normals cancelled; nothing was changed")
                return {"CANCELLED"}
            return report_run(operator, context, done, finished)
    return report_run(operator, context, done, ([], []))


def report_run(operator, context, done: Outcome, baked_run):
    """Reports the operator's run and its bake (``baked_run``: its status lines and failures);
    returns the operator's result."""
    baked, bake_failures = baked_run
    failures = done.failures + bake_failures
    operator.target_missed = "\n".join(done.missed)
    for message in failures:
        operator.report({"ERROR"}, message)
    for message in done.missed:  # a missed target is a warning where the user looks, not a footnote
        operator.report({"WARNING"}, f"TopStoc: {message}")
    if not done.outputs:
        return {"CANCELLED"}
    if operator.output == "NEW_OBJECT":
        select_results(context, done.outputs)
    for line in baked:
        operator.report({"INFO"}, f"TopStoc: {line}")
    seconds = time.perf_counter() - done.started
    if len(done.lines) == 1:
        operator.report({"INFO"}, f"TopStoc: {done.lines[0]}; {seconds:.3f} s with output")
    else:
        operator.report({"INFO"}, f"TopStoc: {len(done.lines)} objects decimated in {seconds:.3f} s")
    return {"FINISHED"}


class TOPSTOC_OT_guided_decimate(OperatorParameters, OperatorBakeParameters, bake_run.BakeModal,
                                 bpy.types.Operator):
    """Decimate the selected meshes with TopStoc, honouring their guidance"""

    bl_idname = "topstoc.guided_decimate"
    bl_label = "Guided Decimate"
    bl_options = {"REGISTER", "UNDO"}

    #: what the last run missed (set by execute, shown in the redo panel)
    target_missed: bpy.props.StringProperty(options={"HIDDEN", "SKIP_SAVE"})

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.selected_meshes_in_object_mode(context))

    def invoke(self, context, event):
        fill_from_scene(self, context.scene.topstoc)  # the panel's settings; the redo panel tweaks them
        self._modal = bake_run.can_run_modal(context)  # a bake then runs modal: progress, Esc cancels
        objects = selected_meshes(context)
        big = sum(pipeline.input_triangles(obj.data) for obj in objects) >= BACKGROUND_TRIANGLES
        if context.window is None or not (big or self.target_mode == "MAX_ERROR"):
            return self.execute(context)
        return self._start_background(context, objects)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "target_mode")
        field = {"RATIO": "ratio", "VERTICES": "vertices", "TRIANGLES": "triangles",
                 "MAX_ERROR": "max_error"}[self.target_mode]
        layout.prop(self, field)
        if self.target_mode == "MAX_ERROR":
            layout.prop(self, "max_error_relative")
        layout.prop(self, "quality")
        row = layout.row(align=True)
        row.prop(self, "use_symmetry")
        row.prop(self, "symmetry_axis", expand=True)
        for name in ("seed", "adaptivity", "density", "placement", "refine", "output"):
            layout.prop(self, name)
        for line in filter(None, self.target_missed.split("\n")):
            layout.label(text=line, icon="ERROR")
        draw_bake(layout, self)

    def execute(self, context):
        explicit_engine_options(self)
        done = Outcome(time.perf_counter())
        for obj in selected_meshes(context):
            try:
                write_run(self, pipeline.decimate(context, obj, self, region_3d=context.region_data), done)
            except TopStocError as error:
                done.failures.append(str(error))
        return conclude(self, context, done)

    # -- the run on a worker thread (modal) -----------------------------------------------------

    def _start_background(self, context, objects):
        """Reads every object (main thread) and hands the rest to a worker; the modal polls it."""
        explicit_engine_options(self)
        self.done = Outcome(time.perf_counter())
        reads = []
        for obj in objects:
            try:
                reads.append(pipeline.read_input(context, obj, self, region_3d=context.region_data))
            except TopStocError as error:
                self.done.failures.append(str(error))
        if not reads:
            return conclude(self, context, self.done)
        self.job = BackgroundDecimation(reads, deferred=True)  # begun by the first modal event
        self.timer = context.window_manager.event_timer_add(0.1, window=context.window)
        context.window_manager.modal_handler_add(self)
        self._in_modal = True  # a bake started after the decimations reuses this modal handler
        context.window_manager.progress_begin(0, 100)
        self._show(context)
        return {"RUNNING_MODAL"}

    def _status(self, context, text):
        if context.area is not None:
            context.area.header_text_set(text)
        context.workspace.status_text_set(text)

    def _show(self, context):
        fraction, line = self.job.progress()
        context.window_manager.progress_update(int(100 * fraction))
        self._status(context, f"TopStoc Guided Decimate: {line}   Esc: cancel")

    def _stop(self, context):
        context.window_manager.event_timer_remove(self.timer)
        context.window_manager.progress_end()
        self._status(context, None)

    def bake_finished(self, context, baked_run):
        return report_run(self, context, self._done, baked_run)

    def modal(self, context, event):
        if getattr(self, "_bake", None) is not None:  # the decimations are written; the bake steps
            return bake_run.BakeModal.modal(self, context, event)
        self.job.begin()  # after invoke has returned to Blender (BackgroundDecimation.begin)
        if event.type == "ESC" and event.value == "PRESS":
            self.job.cancel()
            self._stop(context)
            self.report({"WARNING"}, "TopStoc: Guided Decimate cancelled; nothing was changed")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"} if event.type in NAVIGATION else {"RUNNING_MODAL"}
        try:
            if not self.job.finished():
                self._show(context)
                return {"RUNNING_MODAL"}
        except Exception as error:  # noqa: BLE001 - the engine's unexpected error, said where the user looks
            self._stop(context)
            self.report({"ERROR"}, f"TopStoc: {error}")
            return {"CANCELLED"}
        self._stop(context)
        for run, failure in self.job.outcomes:
            try:
                if failure is not None:
                    raise pipeline.DecimationError(failure)
                write_run(self, run, self.done)
            except TopStocError as error:
                self.done.failures.append(str(error))
            except ReferenceError:  # removed by a script while it was decimated
                self.done.failures.append("an object was removed while it was decimated")
        return conclude(self, context, self.done)


CLASSES = (TOPSTOC_OT_guided_decimate,)
