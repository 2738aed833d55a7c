"""Poll checks that say why a button is greyed out (Blender 3.0+ shows the message in the
tooltip through ``poll_message_set``; older versions just grey the button).

Each check returns None when the operator can run, else the reason in plain words.
"""

from __future__ import annotations


def refuse(cls, reason) -> bool:
    """The poll result for ``reason`` (None: allowed), telling Blender why when refused."""
    if reason is None:
        return True
    if hasattr(cls, "poll_message_set"):
        cls.poll_message_set(reason)
    return False


def active_mesh(context):
    """Reason unless the active object is a mesh."""
    obj = context.active_object
    if obj is None:
        return "Select a mesh object first"
    if obj.type != "MESH":
        return f"'{obj.name}' is not a mesh (it is a {obj.type.lower()})"
    return None


def object_mode(context):
    if context.mode != "OBJECT":
        return "Switch to Object Mode first"
    return None


def active_mesh_in_object_mode(context):
    return active_mesh(context) or object_mode(context)


def selected_meshes_in_object_mode(context):
    if not any(obj.type == "MESH" for obj in context.selected_objects):
        return "Select one or more mesh objects"
    return object_mode(context)


def view_3d(context):
    if context.area is None or context.area.type != "VIEW_3D":
        return "Run this from a 3D Viewport"
    return None
