"""The clean-up operator: remove every small handle and tunnel, fill every small hole in one
step (topstoc.core.api.clean, docs/design.md §4.6), with undo, on the active mesh."""

from __future__ import annotations

import bpy
from bpy.props import FloatProperty, IntProperty

from ...core.api.clean import clean
from . import polls
from .topology import _why_not_editable, run_edit


class TOPSTOC_OT_clean(bpy.types.Operator):
    """Remove every handle or tunnel whose shortest loop is below the size and fill every hole \
below the size; the rest of the surface stays exactly as it was"""

    bl_idname = "topstoc.clean"
    bl_label = "Clean Up Small Handles and Holes"
    bl_options = {"REGISTER", "UNDO"}

    max_handle: FloatProperty(name="Handle Size", description="Remove handles whose shortest loop is shorter than "
                              "this percentage of the bounding box's diagonal", default=1.0, min=0.0, max=100.0,
                              subtype="PERCENTAGE")
    max_hole: FloatProperty(name="Hole Size", description="Fill holes whose border is shorter than this percentage "
                            "of the bounding box's diagonal", default=1.0, min=0.0, max=100.0, subtype="PERCENTAGE")
    keep_largest: IntProperty(name="Keep Largest", description="Keep at least this many handles, the largest "
                              "(-1: keep only those above the size)", default=-1, min=-1)

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, _why_not_editable(context))

    def execute(self, context):
        report = {}

        def compute(obj, arrays):
            result = clean(arrays.vertices, arrays.triangles, max_handle=f"{self.max_handle}%",
                           max_hole=f"{self.max_hole}%", keep_largest=None if self.keep_largest < 0 else self.keep_largest)
            report["result"] = result
            return result.edit

        status = run_edit(self, context, compute, verb="cleaned")
        result = report.get("result")
        if result is not None and status == {"FINISHED"}:
            handles = result.count("handle") + result.count("tunnel")
            self.report({"INFO"}, f"TopStoc: removed {handles} handles (genus {result.genus_before} -> "
                                  f"{result.genus_after}), filled {result.count('hole')} holes, "
                                  f"left {len(result.left)} loops or holes above the size or unremovable")
        return status


CLASSES = (TOPSTOC_OT_clean,)
