"""Blender-facing part of the add-on (needs bpy). Filled in by the add-on work."""


def register():
    pass


def unregister():
    pass
