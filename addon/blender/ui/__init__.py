"""Panels in the 3D view's sidebar, tab "TopStoc": decimation, topology, metrics (and their sub-panels)."""

import bpy

from . import metrics, panels, topology

MODULES = (panels, topology, metrics)


def register():
    for module in MODULES:
        for cls in module.CLASSES:
            bpy.utils.register_class(cls)


def unregister():
    for module in reversed(MODULES):
        for cls in reversed(module.CLASSES):
            bpy.utils.unregister_class(cls)
