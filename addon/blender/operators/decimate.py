"""The one-click "Guided Decimate" operator (object mode, every selected mesh)."""

from __future__ import annotations

import time

import bpy

from ..decimation import pipeline
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
        return self.execute(context)

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
        start = time.perf_counter()
        outputs, lines, failures, sources, missed = [], [], [], [], []
        for obj in selected_meshes(context):
            try:
                run = pipeline.decimate(context, obj, self, region_3d=context.region_data)
                if self.output == "NEW_OBJECT":
                    pipeline.store_samples(run)
                outputs.append(pipeline.write_output(run, self.output))
                sources.append(obj)
                lines.append(pipeline.summary(run))
                if run.result.stats.target_missed is not None:
                    missed.append(f"{obj.name}: {run.result.stats.target_missed.text()}")
            except TopStocError as error:
                failures.append(str(error))
        self._run = (start, outputs, lines, failures, missed)
        if self.bake_normals and outputs:
            if self.output != "NEW_OBJECT":
                failures.append("Bake Normals needs Output: New Object (in place, no original is left to "
                                "bake from)")
            elif getattr(self, "_modal", False):
                return self.start_bake(context, list(zip(sources, outputs)), outputs)
            else:
                done = bake_run.bake_or_discard(context, self, zip(sources, outputs), outputs)
                if done is None:
                    self.report({"WARNING"}, "TopStoc: Bake Normals cancelled; nothing was changed")
                    return {"CANCELLED"}
                return report_run(self, context, done)
        return report_run(self, context, ([], []))

    def bake_finished(self, context, done):
        return report_run(self, context, done)


def report_run(operator, context, done):
    """Reports the operator's run (and its bake: ``done``, its status lines and failures); returns
    the operator's result."""
    start, outputs, lines, failures, missed = operator._run
    baked, bake_failures = done
    failures = failures + bake_failures
    operator.target_missed = "\n".join(missed)
    for message in failures:
        operator.report({"ERROR"}, message)
    for message in missed:  # a missed target is a warning where the user looks, not a footnote
        operator.report({"WARNING"}, f"TopStoc: {message}")
    if not outputs:
        return {"CANCELLED"}
    if operator.output == "NEW_OBJECT":
        select_results(context, outputs)
    for line in baked:
        operator.report({"INFO"}, f"TopStoc: {line}")
    seconds = time.perf_counter() - start
    if len(lines) == 1:
        operator.report({"INFO"}, f"TopStoc: {lines[0]}; {seconds:.3f} s with output")
    else:
        operator.report({"INFO"}, f"TopStoc: {len(lines)} objects decimated in {seconds:.3f} s")
    return {"FINISHED"}


CLASSES = (TOPSTOC_OT_guided_decimate,)
