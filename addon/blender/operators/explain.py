"""The "?" buttons: a one-line explanation as the tooltip, and in the status bar when clicked."""

from __future__ import annotations

import bpy

from ..ui.topology_help import HELP


class TOPSTOC_OT_explain(bpy.types.Operator):
    """Explain this figure in plain words"""

    bl_idname = "topstoc.explain"
    bl_label = "Explain"
    bl_options = {"INTERNAL"}

    topic: bpy.props.StringProperty(options={"HIDDEN", "SKIP_SAVE"})

    @classmethod
    def description(cls, context, properties):
        return HELP.get(properties.topic, cls.__doc__)

    def execute(self, context):
        self.report({"INFO"}, HELP.get(self.topic, "No help for this item"))
        return {"FINISHED"}


CLASSES = (TOPSTOC_OT_explain,)
