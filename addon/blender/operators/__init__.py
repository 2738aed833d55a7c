"""Operators, one module per concern; each module lists its classes in CLASSES."""

import bpy

from . import decimate, guidance, metrics, preview, samples, topology, variants

MODULES = (decimate, guidance, preview, samples, variants, topology, metrics)


def register():
    for module in MODULES:
        for cls in module.CLASSES:
            bpy.utils.register_class(cls)


def unregister():
    topology.cancel_all()
    for module in reversed(MODULES):
        for cls in reversed(module.CLASSES):
            bpy.utils.unregister_class(cls)
