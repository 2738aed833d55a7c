"""The add-on's drawing code avoids what Blender 5.x removed from the Python GPU API: the ``bgl``
module, the ``GPUShader(vertex, fragment)`` constructor, built-in shader names dropped in 4.0
("2D_"/"3D_" prefixes) and vertex formats with attributes of fewer than 4 bytes per component."""

import ast
import pathlib

ADDON = pathlib.Path(__file__).resolve().parents[2] / "addon"
# Built-in shaders present in Blender 3.4 through 5.x (the add-on must run in all of them).
PORTABLE_BUILTINS = {"UNIFORM_COLOR", "SMOOTH_COLOR", "FLAT_COLOR", "POLYLINE_UNIFORM_COLOR",
                     "POLYLINE_SMOOTH_COLOR", "POLYLINE_FLAT_COLOR", "IMAGE", "IMAGE_COLOR"}
POINT_BUILTINS = {"POINT_UNIFORM_COLOR"}  # 4.0+: used only with a fallback to UNIFORM_COLOR


def _calls(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            yield node, ast.unparse(node.func)


def test_no_removed_gpu_api_in_the_addon():
    sources = sorted(ADDON.rglob("*.py"))
    assert sources
    builtins_used = set()
    for path in sources:
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] + [getattr(node, "module", None) or ""]
                assert "bgl" not in names, f"{path}: imports bgl (removed in Blender 5.0)"
        for call, name in _calls(tree):
            assert not name.endswith("GPUShader"), f"{path}:{call.lineno}: GPUShader(vertex, fragment) constructor"
            if name.endswith("attr_add"):
                kinds = [k.value for k in call.keywords if k.arg == "comp_type"]
                assert all(k in ("F32", "I32", "U32") for k in kinds), f"{path}:{call.lineno}: unaligned {kinds}"
            if name.endswith("from_builtin"):
                builtins_used.update(a.value for a in call.args if isinstance(a, ast.Constant))
    assert builtins_used, "the overlays should draw with built-in shaders"
    assert builtins_used <= PORTABLE_BUILTINS | POINT_BUILTINS, builtins_used - PORTABLE_BUILTINS - POINT_BUILTINS
