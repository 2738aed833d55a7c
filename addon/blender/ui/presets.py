"""Blender presets of the decimation settings (the preset menu at the top of the panel).

The bundled presets (preset_files/: "Game LOD", "Scan Clean-up", "Hard Surface", "Symmetric
Character") are copied into the user's preset folder ``scripts/presets/topstoc/decimate`` on
registration, where Blender's preset menu finds them and where the "+" button saves new ones.
A preset the user already has (or changed) is never overwritten.
"""

from __future__ import annotations

import os
import shutil

import bpy
from bl_operators.presets import AddPresetBase

PRESET_SUBDIR = "topstoc/decimate"
BUNDLED = os.path.join(os.path.dirname(__file__), "preset_files")
#: the settings a preset stores (guidance stays per object, output placement per use)
PRESET_SETTINGS = ("target_mode", "ratio", "vertices", "triangles", "max_error", "max_error_relative",
                   "quality", "use_symmetry", "symmetry_axis", "seed", "adaptivity", "density",
                   "placement", "refine", "output")


def user_preset_folder(create: bool = True) -> str:
    return bpy.utils.user_resource("SCRIPTS", path=os.path.join("presets", PRESET_SUBDIR), create=create)


def install_bundled() -> list:
    """Copies the bundled presets the user does not have yet; returns the paths written."""
    try:
        folder = user_preset_folder()
    except (OSError, ValueError):  # read-only home: the menu simply stays empty
        return []
    written = []
    for name in sorted(os.listdir(BUNDLED)):
        target = os.path.join(folder, name)
        if name.endswith(".py") and not os.path.exists(target):
            try:
                shutil.copyfile(os.path.join(BUNDLED, name), target)
                written.append(target)
            except OSError:
                pass
    return written


class TOPSTOC_MT_presets(bpy.types.Menu):
    """Presets of the decimation settings """

    bl_label = "Presets"
    preset_subdir = PRESET_SUBDIR
    preset_operator = "script.execute_preset"
    draw = bpy.types.Menu.draw_preset


class TOPSTOC_OT_preset_add(AddPresetBase, bpy.types.Operator):
    """Save the current decimation settings as a preset (or remove the active one)"""

    bl_idname = "topstoc.preset_add"
    bl_label = "Add Decimation Preset"
    preset_menu = "TOPSTOC_MT_presets"
    preset_subdir = PRESET_SUBDIR
    preset_defines = ["settings = bpy.context.scene.topstoc"]
    preset_values = [f"settings.{name}" for name in PRESET_SETTINGS]


CLASSES = (TOPSTOC_MT_presets, TOPSTOC_OT_preset_add)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    install_bundled()


def unregister():
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
