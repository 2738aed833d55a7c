"""The clean-up operator: remove every small handle and tunnel, fill every small hole in one
step (topstoc.core.api.clean, docs/design.md §4.6), with undo, on the active mesh.

From the interface it first shows what it will do (analysis/clean_plan.py): the loops and holes
it removes in green, those it leaves in violet, the counts in the header and the panel; Enter
applies exactly that, Esc leaves the mesh as it was, + and - grow and shrink both sizes. Run
from a script (or in background mode) it applies at once.
"""

from __future__ import annotations

import bpy
from bpy.props import FloatProperty, IntProperty

from ..analysis import clean_plan
from ..io import mesh_read
from . import polls
from .topology import _mesh_object, _redraw_panels, _why_not_editable, run_edit

#: How much + and - change both sizes during the preview.
SIZE_STEP = 1.5


class TOPSTOC_OT_clean(bpy.types.Operator):
    """Remove every handle or tunnel whose shortest loop is below the size and fill every hole \
below the size; the rest of the surface stays exactly as it was. Shows what it will remove first \
(Enter applies, Esc cancels)"""

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

    def _plan(self, obj, arrays) -> clean_plan.Plan:
        return clean_plan.plan(obj, arrays, f"{self.max_handle}%", f"{self.max_hole}%",
                               None if self.keep_largest < 0 else self.keep_largest)

    def execute(self, context):
        obj = _mesh_object(context)
        made = {}

        def compute(target, arrays):
            made["plan"] = self._plan(target, arrays)  # the previewed plan when the mesh and sizes are its
            return made["plan"].result.edit

        status = run_edit(self, context, compute, verb="cleaned", carry=False)
        clean_plan.hide(obj)
        if "plan" in made and status == {"FINISHED"}:
            result = made["plan"].result
            topology = obj.topstoc.topology
            if topology.loops_state == "OK":  # the searched loops were dropped: most went with their handles
                topology.loops_state, topology.loops_message = "NONE", "Cleaned: Find Loops lists what is left"
            text = f"TopStoc: {made['plan'].summary()} (genus {result.genus_before} -> {result.genus_after})"
            obj.topstoc.topology.edit_message = text[len("TopStoc: "):].capitalize()
            self.report({"INFO"}, text)
        return status

    def invoke(self, context, event):
        if context.window is None or bpy.app.background or context.area is None:
            return self.execute(context)
        obj = _mesh_object(context)
        if not self._preview(context, obj):
            return {"CANCELLED"}
        self.object_name = obj.name
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _preview(self, context, obj) -> bool:
        """Makes and shows the plan for the present sizes; False (reported) when it cannot."""
        if obj.mode == "EDIT":
            obj.update_from_editmode()  # the mesh data as the edit mesh is now
        try:
            shown = self._plan(obj, mesh_read.read_mesh(obj.data))
        except ValueError as error:
            self.report({"ERROR"}, f"TopStoc: '{obj.name}': {error}")
            return False
        clean_plan.show(obj, shown)
        context.area.header_text_set(
            f"Clean-up preview (handles < {self.max_handle:.3g} %, holes < {self.max_hole:.3g} % of the diagonal): "
            f"{shown.summary()}   Enter: apply   Esc: cancel   +/-: sizes")
        _redraw_panels(context)
        return True

    def _end_preview(self, context, obj) -> None:
        clean_plan.hide(obj)
        if context.area is not None:
            context.area.header_text_set(None)
        _redraw_panels(context)

    def modal(self, context, event):
        obj = bpy.data.objects.get(self.object_name)
        if obj is None or context.active_object != obj:
            self._end_preview(context, obj)
            return {"CANCELLED"}
        if event.value != "PRESS":
            return {"PASS_THROUGH"}
        if event.type in {"RET", "NUMPAD_ENTER"}:
            if context.area is not None:
                context.area.header_text_set(None)
            return self.execute(context)
        if event.type in {"ESC", "RIGHTMOUSE"}:
            self._end_preview(context, obj)
            self.report({"INFO"}, "TopStoc: clean-up cancelled; nothing changed")
            return {"CANCELLED"}
        if event.type in {"NUMPAD_PLUS", "EQUAL", "NUMPAD_MINUS", "MINUS"}:
            factor = SIZE_STEP if event.type in {"NUMPAD_PLUS", "EQUAL"} else 1 / SIZE_STEP
            self.max_handle, self.max_hole = min(100.0, self.max_handle * factor), min(100.0, self.max_hole * factor)
            if not self._preview(context, obj):
                self._end_preview(context, obj)
                return {"CANCELLED"}
            return {"RUNNING_MODAL"}
        return {"PASS_THROUGH"}  # orbit, zoom and pan to look at the preview


CLASSES = (TOPSTOC_OT_clean,)
