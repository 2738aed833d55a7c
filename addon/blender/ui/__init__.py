"""Panels in the 3D view's sidebar, tab "TopStoc" (more panels slot in here: topology, metrics)."""

import bpy

from . import panels

MODULES = (panels,)


def register():
    for module in MODULES:
        for cls in module.CLASSES:
            bpy.utils.register_class(cls)


def unregister():
    for module in reversed(MODULES):
        for cls in reversed(module.CLASSES):
            bpy.utils.unregister_class(cls)
