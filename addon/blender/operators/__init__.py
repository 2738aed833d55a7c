"""Operators, one module per concern; each module lists its classes in CLASSES."""

import bpy

from . import (clean, decimate, explain, frame_loop, guidance, import_off, metrics, preview, regenerate, samples,
               topology, variants)

MODULES = (decimate, guidance, preview, samples, variants, regenerate, topology, frame_loop, metrics, import_off,
           explain, clean)


def register():
    for module in MODULES:
        for cls in module.CLASSES:
            bpy.utils.register_class(cls)
    import_off.register_menu()


def unregister():
    topology.cancel_all()
    import_off.unregister_menu()
    for module in reversed(MODULES):
        for cls in reversed(module.CLASSES):
            bpy.utils.unregister_class(cls)
