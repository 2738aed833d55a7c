"""TopStoc: fast user-guided mesh decimation with topology control.

The package works in three places: as a plain Python package (``import topstoc``, no Blender
needed; see ``topstoc.core``), as a legacy add-on in Blender 3.x (``bl_info`` below) and as an
extension in Blender 4.2+ (``blender_manifest.toml`` next to this file). Importing it never
imports ``bpy``; only register() does.
"""

bl_info = {
    "name": "TopStoc",
    "author": "TopStoc developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > TopStoc",
    "description": "Fast guided decimation with topology control",
    "category": "Mesh",
}

#: The package version: bl_info's is the one place it is set (pyproject.toml, CMakeLists.txt and
#: blender_manifest.toml repeat it; tests/python/test_cli_messages.py checks that they agree).
__version__ = ".".join(map(str, bl_info["version"]))


def __getattr__(name):
    """``topstoc.Mesh`` etc.: the core API, loaded on first use (PEP 562).

    Only public names are looked up in topstoc.core: private names and submodules must fall
    through, because ``from topstoc import _topstoc`` probes the attribute before importing.
    """
    if name.startswith("_") or name in ("core", "blender", "batch"):
        raise AttributeError(f"module 'topstoc' has no attribute {name!r}")
    from . import core

    try:
        return getattr(core, name)
    except AttributeError:
        raise AttributeError(f"module 'topstoc' has no attribute {name!r}") from None


def register():
    """Registers the Blender add-on (needs bpy)."""
    from .blender import register as register_blender

    register_blender()


def unregister():
    """Unregisters everything register() added."""
    from .blender import unregister as unregister_blender

    unregister_blender()
