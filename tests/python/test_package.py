"""The package: extension manifest, bl_info, and imports without Blender."""

import pathlib
import subprocess
import sys
import tomllib

import topstoc
from conftest import bare_env

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
    staged = tomllib.loads((package / "blender_manifest.toml").read_text())
    release = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
    # The staged package holds its module itself: the release's topstoc_native wheels are dropped.
    assert "wheels" not in staged and len(release.pop("wheels")) == 4
    assert staged == release
    assert list(package.glob("_topstoc*.so"))


def test_import_never_needs_bpy():
    code = ("import sys; sys.modules['bpy'] = None\n"  # any attempt to import bpy fails
            "import topstoc, topstoc.core\n"
            "m = topstoc.Mesh(*__import__('meshgen').icosphere(2))\n"
            "print(m.decimate(ratio=0.5).num_vertices)")
    tests = str(ROOT / "tests")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=bare_env(PYTHONPATH=f"{pathlib.Path(topstoc.__file__).parents[1]}:{tests}"))
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) == 81


def test_manifest_lists_the_native_wheel_for_each_blender_python_and_platform():
    """Blender 4.2-5.0 embed CPython 3.11, 5.1+ CPython 3.13: one topstoc_native wheel each, for
    Linux x86-64 and arm64, at glibc 2.28 (RHEL/Rocky 8, the VFX Reference Platform's oldest)."""
    import re

    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text())
    assert manifest["platforms"] == ["linux-x64", "linux-arm64"]
    pattern = re.compile(r"\./wheels/topstoc_native-(?P<version>[^-]+)-(?P<py>cp3\d+)-(?P=py)-"
                         r"manylinux_2_(?P<glibc>\d+)_(?P<arch>x86_64|aarch64)\.whl")
    matches = [pattern.fullmatch(w) for w in manifest["wheels"]]
    assert all(matches), manifest["wheels"]
    assert sorted((m["py"], m["arch"]) for m in matches) == [
        ("cp311", "aarch64"), ("cp311", "x86_64"), ("cp313", "aarch64"), ("cp313", "x86_64")]
    assert {m["version"] for m in matches} == {manifest["version"]}
    assert all(int(m["glibc"]) <= 28 for m in matches)


def test_the_native_distribution_is_built_from_the_same_project_and_version():
    """packaging/topstoc_native/pyproject.toml (the extension's wheel, built by cibuildwheel)
    builds this CMake project at the package's version into the package topstoc_native only."""
    package = tomllib.loads((ROOT / "pyproject.toml").read_text())
    native_dir = ROOT / "packaging" / "topstoc_native"
    native = tomllib.loads((native_dir / "pyproject.toml").read_text())
    assert native["project"]["name"] == "topstoc_native"
    assert native["project"]["version"] == package["project"]["version"]
    assert native["project"]["license"] == package["project"]["license"]
    cmake = native["tool"]["scikit-build"]["cmake"]
    assert (native_dir / cmake["source-dir"]).resolve() == ROOT
    assert cmake["define"]["TOPSTOC_WHEEL_PACKAGE"] == "topstoc_native"
    assert "TOPSTOC_WHEEL_PACKAGE" not in package["tool"]["scikit-build"]["cmake"]["define"]
