"""Samples as data (thesis 4.1.3): keep a decimation's samples on the object, restore it later."""

from __future__ import annotations

import bpy
from bpy.props import StringProperty

from ..decimation import pipeline
from ...core.support.errors import TopStocError
from . import polls


class TOPSTOC_OT_save_samples(bpy.types.Operator):
    """Keep the last decimation's samples under a name"""

    bl_idname = "topstoc.save_samples"
    bl_label = "Save Samples"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(name="Name", default="Samples")

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh(context)
        if reason is None and pipeline.LAST_SAMPLES not in context.active_object.topstoc.sample_sets:
            reason = "Run Guided Decimate (New Object) first: it remembers the samples it used"
        return polls.refuse(cls, reason)

    def execute(self, context):
        sets = context.object.topstoc.sample_sets
        last = sets[pipeline.LAST_SAMPLES]
        entry = sets.get(self.name) or sets.add()
        entry.name = self.name
        for key in ("parameters", "mesh_digest", "layout_digest", "vertices_out", "triangles_out"):
            setattr(entry, key, getattr(last, key))
        entry["samples"] = last["samples"]
        return {"FINISHED"}


class TOPSTOC_OT_restore_samples(bpy.types.Operator):
    """Re-create a saved decimation exactly, as a new object"""

    bl_idname = "topstoc.restore_samples"
    bl_label = "Restore Samples"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(name="Name", default=pipeline.LAST_SAMPLES)

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh_in_object_mode(context)
        if reason is None and not len(context.active_object.topstoc.sample_sets):
            reason = "This object has no saved samples"
        return polls.refuse(cls, reason)

    def execute(self, context):
        obj = context.object
        try:
            run = pipeline.restore(context, obj, self.name)
        except TopStocError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        out = pipeline.write_output(run, "NEW_OBJECT", name=f"{obj.name}_{self.name}")
        self.report({"INFO"}, f"TopStoc: restored '{self.name}': {pipeline.summary(run)}")
        out.select_set(True)
        return {"FINISHED"}


class TOPSTOC_OT_remove_samples(bpy.types.Operator):
    """Forget a saved sample set"""

    bl_idname = "topstoc.remove_samples"
    bl_label = "Remove Samples"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(name="Name")

    def execute(self, context):
        sets = context.object.topstoc.sample_sets
        index = sets.find(self.name)
        if index < 0:
            return {"CANCELLED"}
        sets.remove(index)
        return {"FINISHED"}


CLASSES = (TOPSTOC_OT_save_samples, TOPSTOC_OT_restore_samples, TOPSTOC_OT_remove_samples)
