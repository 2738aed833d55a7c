"""Regenerate: re-run a result's decimation on its source's current mesh (regenerate.py)."""

from __future__ import annotations

import bpy

from ..decimation import pipeline
from ..preview import regenerate
from ..decimation.guidance import GuidanceError
from . import polls


class TOPSTOC_OT_regenerate(bpy.types.Operator):
    """Decimate the source again with this result's settings and replace the result's mesh \
(its transform, modifiers and materials stay)"""

    bl_idname = "topstoc.regenerate"
    bl_label = "Regenerate"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        reason = polls.object_mode(context) or regenerate.why_not(context.active_object)
        return polls.refuse(cls, reason)

    def execute(self, context):
        result_obj = context.active_object
        try:
            run = regenerate.regenerate(context, result_obj)
        except (pipeline.DecimationError, GuidanceError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"TopStoc: regenerated {result_obj.name}: {pipeline.summary(run)}")
        return {"FINISHED"}


CLASSES = (TOPSTOC_OT_regenerate,)
