"""The package: extension manifest, bl_info, and imports without Blender."""

import pathlib
import subprocess
import sys
import tomllib

import topstoc

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_manifest_has_the_keys_blender_4_2_requires():
    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
    assert manifest["schema_version"] == "1.0.0"
    assert manifest["id"] == "topstoc" and manifest["id"].isidentifier()
    assert manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    for key in ("name", "tagline", "maintainer", "version"):
        assert isinstance(manifest[key], str) and manifest[key]
    assert len(manifest["tagline"]) <= 64 and not manifest["tagline"].endswith(".")
    assert manifest["license"] and all(item.startswith("SPDX:") for item in manifest["license"])


def test_manifest_version_matches_bl_info():
    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
    assert manifest["version"] == ".".join(str(x) for x in topstoc.bl_info["version"])
    assert topstoc.bl_info["blender"] >= (3, 4, 0)
    assert topstoc.bl_info["name"] == manifest["name"]


def test_staged_package_has_the_manifest_next_to_init():
    package = pathlib.Path(topstoc.__file__).parent
    assert (package / "blender_manifest.toml").read_text() == (ROOT / "blender_manifest.toml").read_text()
    assert list(package.glob("_topstoc*.so"))


def test_import_never_needs_bpy():
    code = ("import sys; sys.modules['bpy'] = None\n"  # any attempt to import bpy fails
            "import topstoc, topstoc.core\n"
            "m = topstoc.Mesh(*__import__('meshgen').icosphere(2))\n"
            "print(m.decimate(ratio=0.5).num_vertices)")
    tests = str(ROOT / "tests")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={"PYTHONPATH": f"{pathlib.Path(topstoc.__file__).parents[1]}:{tests}"})
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) == 81
