"""The add-on registers and unregisters cleanly; panels reference only real properties/operators."""

import importlib
import importlib.util
import sys

import addon_utils
import bpy
import pytest

import meshgen
from helpers import make_object

OPERATORS = ("guided_decimate", "preview", "set_guidance", "add_guidance_layer", "show_guidance", "add_box",
             "multiview", "lod_chain", "save_samples", "restore_samples", "remove_samples",
             "measure", "write_error_colors", "turntable", "analyse", "find_loops", "loop_step", "select_loop",
             "cut_loop", "remove_loop", "fill_holes", "delete_faces", "clean", "frame_loop")
PANEL_MODULES = ("panels", "topology", "metrics")


def test_unregister_and_register_again(ts, addon_module):
    assert all(hasattr(bpy.ops.topstoc, name) for name in OPERATORS)
    addon_utils.disable(addon_module, default_set=True)
    assert not hasattr(bpy.types.Scene, "topstoc") and not hasattr(bpy.types.Object, "topstoc")
    assert not hasattr(bpy.types, "TOPSTOC_PT_decimate")
    assert all(not hasattr(bpy.types, f"TOPSTOC_OT_{name}") for name in OPERATORS)
    assert addon_utils.enable(addon_module, default_set=True) is not None
    assert hasattr(bpy.types.Scene, "topstoc")
    assert bpy.ops.topstoc.guided_decimate.idname() == "TOPSTOC_OT_guided_decimate"
    if bpy.app.version >= (4, 2, 0):
        assert addon_module.startswith("bl_ext."), "Blender 4.2+ runs the add-on as an extension"


def test_import_needs_no_bpy_for_core(ts):
    # The package's own __init__ must not import bpy; only register() does.
    source = importlib.util.find_spec(ts.__name__).origin
    text = open(source).read()
    assert "import bpy" not in text.split("def register")[0]


class RecordingLayout:
    """Stands in for bpy's UILayout: checks every property and operator a panel names."""

    def __init__(self, seen):
        self.seen = seen

    def __getattr__(self, name):
        if name in ("row", "column", "box", "split", "column_flow", "grid_flow"):
            return lambda *a, **k: RecordingLayout(self.seen)
        if name in ("prop", "prop_search"):
            def prop(data, attribute, *args, **kw):
                assert hasattr(data, attribute) or attribute in data.bl_rna.properties, attribute
                if name == "prop_search":
                    assert hasattr(args[0], args[1]), args[1]
                self.seen.add(attribute)
            return prop
        if name == "operator":
            def operator(idname, **kw):
                group, op = idname.split(".")
                assert hasattr(getattr(bpy.ops, group), op), idname
                self.seen.add(idname)
                return type("Props", (), {})()
            return operator
        return lambda *a, **k: None


def fake_panel(cls, seen):
    """Stands in for an instance of panel ``cls`` (only Blender makes those): a recording layout
    and the panel's own methods that its draw calls on self."""
    methods = {name: getattr(cls, name) for name in ("draw_mesh", "draw_settings", "draw_analysed")
               if hasattr(cls, name)}
    return type("P", (), {"layout": RecordingLayout(seen), **methods})()


@pytest.mark.parametrize("kind", ["mesh", "empty"])
def test_panels_draw(ts, scene, kind):
    obj = make_object("Ball", *meshgen.icosphere(1))
    obj.data.materials.append(bpy.data.materials.new("M"))
    obj.topstoc.use_vertex_group = True
    scene.topstoc.use_view = True
    scene.topstoc.use_frustum = True
    if kind == "empty":
        obj = bpy.data.objects.new("Box", None)
        scene.collection.objects.link(obj)
        bpy.context.view_layer.objects.active = obj
    seen = set()
    for name in PANEL_MODULES:
        module = importlib.import_module(f"{ts.__name__}.blender.ui.{name}")
        for cls in module.CLASSES:
            if issubclass(cls, bpy.types.UIList):
                continue
            fake = fake_panel(cls, seen)
            for mode in ("RATIO", "VERTICES", "TRIANGLES", "MAX_ERROR"):
                scene.topstoc.target_mode = mode
                if hasattr(cls, "draw_header"):
                    cls.draw_header(fake, bpy.context)
                cls.draw(fake, bpy.context)
    assert "topstoc.guided_decimate" in seen
    assert ("use_color" in seen) == (kind == "mesh") and ("box_weight" in seen) == (kind == "empty")


def _extension_cli():
    import pathlib

    root = pathlib.Path(bpy.utils.resource_path("LOCAL")) / "scripts" / "addons_core" / "bl_pkg" / "cli"
    script = root / "blender_ext.py"
    return script if script.exists() else None


@pytest.mark.skipif(bpy.app.version < (4, 2, 0), reason="extensions exist from Blender 4.2")
def test_manifest_validates_as_an_extension(ts):
    import subprocess

    from conftest import PACKAGE

    script = _extension_cli()
    if script is None:
        pytest.skip("Blender's extension command line (bl_pkg) is not available")
    done = subprocess.run([sys.executable, str(script), "validate", str(PACKAGE)], capture_output=True, text=True)
    assert done.returncode == 0 and "Success" in done.stdout, done.stdout + done.stderr
