"""Blender-facing part of the add-on (needs bpy): settings, operators, panels, overlays.

Sub-packages register in order and unregister in reverse; the prepared-mesh cache is emptied
when a file is loaded and on unregister. Overlays add their draw handlers only outside
background mode.
"""

import bpy
from bpy.app.handlers import persistent

from . import operators, props, ui
from .ui import overlays, presets
from .preview import regenerate, watch
from .preview.cache import prepared_meshes

MODULES = (props, operators, presets, ui, watch, regenerate, overlays)


@persistent
def _clear_cache(*_args):
    prepared_meshes.clear()


def register():
    for module in MODULES:
        module.register()
    bpy.app.handlers.load_post.append(_clear_cache)


def unregister():
    if _clear_cache in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_clear_cache)
    for module in reversed(MODULES):
        module.unregister()
    prepared_meshes.clear()
