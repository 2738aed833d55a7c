"""What ships installs and runs where none of the build's libraries exist (issue 15).

- `pip install` of each x86-64 topstoc wheel into a bare venv of a minimal Debian root
  (debootstrap minbase + python3: no TetGen, libgomp, OpenMesh) — Debian 12 for cp311, Debian 13
  for cp313 — then `topstoc decimate` on a bundled mesh; the output must equal the same decimation
  by this checkout's own build, and /proc/PID/maps must show the wheel's module loaded and no
  TetGen, libgomp or OpenMesh library (TetGen and libc++ are linked into the module).
- Debian 13's real Blender 4.3 (CPython 3.13) installs the extension zip from disk, enables it and
  runs Guided Decimate in background; the result is checked against the Python API.

Needs root (chroot), the wheels and the extension zip in dist/ (scripts/build_wheels.sh,
scripts/build_extension.sh) and the cached roots (tests/install/minimal_root.sh,
scripts/debian13_root.sh). numpy comes from a wheelhouse cached on the host, so the roots need
no network.
"""

import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DIST = ROOT / "dist"
CACHE = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc"))
MESH = ROOT / "tests" / "data" / "genus_positive" / "cgal_eight.off"
LINKED_IN = ("libtet", "libgomp", "libOpenMesh")  # none is loaded: TetGen is linked in, no OpenMP, no OpenMesh

sys.path.insert(0, str(ROOT / "build" / "python"))
import topstoc  # noqa: E402  (this checkout's build: the reference)

if os.geteuid() != 0:
    pytest.skip("the install tests need root (chroot)", allow_module_level=True)


def one(pattern: str) -> pathlib.Path:
    found = sorted(DIST.glob(pattern))
    if len(found) != 1:
        pytest.fail(f"expected one dist/{pattern}, found {[f.name for f in found]}: "
                    f"run scripts/build_wheels.sh and scripts/build_extension.sh")
    return found[0]


def run_in(rootfs_cmd: list, work: pathlib.Path, command: str) -> str:
    done = subprocess.run(rootfs_cmd + [str(work), command], capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, f"{command}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    return done.stdout


def wheelhouse(python_tag: str) -> pathlib.Path:
    """numpy for the given CPython, downloaded once from PyPI into the cache."""
    house = CACHE / "wheelhouse" / python_tag
    if not list(house.glob("numpy-*.whl")):
        subprocess.run([str(CACHE / "wheel-venv" / "bin" / "pip"), "download", "-q", "--only-binary=:all:",
                        "--platform", "manylinux2014_x86_64", "--implementation", "cp",
                        "--python-version", python_tag[2] + "." + python_tag[3:], "-d", str(house),
                        "numpy>=1.26,<3"], check=True, timeout=600)
    return house


def reference_decimation(tmp: pathlib.Path) -> str:
    """The same decimation with this checkout's build, as OBJ text."""
    out = tmp / "reference.obj"
    done = subprocess.run([sys.executable, "-m", "topstoc", "decimate", str(MESH), str(out), "--ratio", "0.3"],
                          env={**os.environ, "PYTHONPATH": str(ROOT / "build" / "python")},
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out.read_text()


def mapped(maps: str, name: str) -> list:
    """The shared objects whose file name starts with `name` in /proc/PID/maps."""
    paths = {line.split()[-1] for line in maps.splitlines() if "/" in line and ".so" in line}
    return sorted(p for p in paths if os.path.basename(p).startswith(name))


@pytest.mark.parametrize("suite, tag", [("bookworm", "cp311"), ("trixie", "cp313")])
def test_pip_wheel_runs_topstoc_decimate_in_a_bare_root(tmp_path, suite, tag):
    wheel = one(f"topstoc-*-{tag}-{tag}-manylinux*_x86_64.whl")
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy(wheel, work)
    shutil.copy(MESH, work / "mesh.off")
    shutil.copytree(wheelhouse(tag), work / "wheelhouse")
    root = [str(ROOT / "tests" / "install" / "minimal_root.sh"), suite, "run"]
    # The root really lacks what the build linked.
    missing = run_in(root, work, "ls /usr/lib/x86_64-linux-gnu /lib/x86_64-linux-gnu "
                                 "| grep -E '^(libtet|libgomp|libOpenMesh)' || echo none")
    assert missing.strip() == "none", missing
    out = run_in(root, work, f"""
        python3 -m venv /work/venv &&
        /work/venv/bin/pip install -q --no-index --find-links /work/wheelhouse /work/{wheel.name} &&
        /work/venv/bin/topstoc decimate /work/mesh.off /work/out.obj --ratio 0.3 --json > /work/report.json &&
        /work/venv/bin/python -c "import topstoc.core.support.native, sys; print(open('/proc/self/maps').read())" > /work/maps &&
        ldd /work/venv/lib/python3.*/site-packages/topstoc/_topstoc*.so""")
    assert "not found" not in out, out
    assert (work / "out.obj").read_text() == reference_decimation(tmp_path)
    report = json.loads((work / "report.json").read_text())
    assert report["topology_kept"] is True
    maps = (work / "maps").read_text()
    assert [p for p in mapped(maps, "_topstoc") if "/site-packages/topstoc/" in p], maps
    for name in LINKED_IN:
        assert not mapped(maps, name), (name, mapped(maps, name))


BLENDER_SCRIPT = r"""
import importlib, sys, bpy, addon_utils
name, legacy_zip = sys.argv[-2], sys.argv[-3]
if legacy_zip == "-":  # Debian's Blender 4.3 has no numpy (official builds bundle it)
    sys.path.append("/work/numpy-site")
if legacy_zip != "-":  # Blender 3.x: Preferences > Add-ons > Install...
    bpy.ops.preferences.addon_install(filepath=legacy_zip, overwrite=True)
addon_utils.enable(name, default_set=True)
core = importlib.import_module(name + ".core")
data = core.read_mesh(sys.argv[-1])
mesh = bpy.data.meshes.new("eight")
mesh.from_pydata(data.vertices.tolist(), [], data.triangles.tolist())
mesh.update(calc_edges=True)
obj = bpy.data.objects.new("eight", mesh)
bpy.context.scene.collection.objects.link(obj)
for other in bpy.context.selected_objects:  # the start-up file's cube
    other.select_set(False)
bpy.context.view_layer.objects.active = obj
obj.select_set(True)
result = bpy.ops.topstoc.guided_decimate(target_mode="RATIO", ratio=0.3, output="NEW_OBJECT")
out = bpy.context.view_layer.objects.active
m = out.data
native = importlib.import_module(name + ".core.support.native").engine
print("RESULT", result.pop(), out.name, len(m.vertices), len(m.edges), len(m.polygons))
print("NATIVE", native.__file__)
print("MAPS")
print(open("/proc/self/maps").read())
"""


def test_blender_installs_the_extension_and_runs_guided_decimate(tmp_path):
    zip_file = one("topstoc-*-linux_x64.zip")
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy(zip_file, work)
    shutil.copy(MESH, work / "mesh.off")
    (work / "run.py").write_text(BLENDER_SCRIPT)
    rootfs = subprocess.run([str(ROOT / "scripts" / "debian13_root.sh")], capture_output=True,
                            text=True, check=True).stdout.strip()
    root = [str(ROOT / "scripts" / "in_root.sh"), rootfs]
    missing = run_in(root, work, "ls /usr/lib/x86_64-linux-gnu | grep -E '^(libtet|libOpenMesh)' || echo none")
    assert missing.strip() == "none", missing
    # numpy: Blender's official builds bundle it; Debian's 4.3 neither depends on nor recommends
    # python3-numpy, so run.py puts numpy's own wheel on sys.path, as a Blender with numpy has it.
    shutil.copytree(wheelhouse("cp313"), work / "wheelhouse")
    out = run_in(root, work, f"""
        blender --version | head -1 &&
        python3 -m zipfile -e /work/wheelhouse/numpy-*.whl /work/numpy-site &&
        blender -b --command extension install-file -r user_default /work/{zip_file.name} &&
        blender -b --python-exit-code 1 --python /work/run.py -- - bl_ext.user_default.topstoc /work/mesh.off""")
    assert "Blender 4.3" in out
    check_blender_result(out)
    native_file = next(l for l in out.splitlines() if l.startswith("NATIVE")).split(maxsplit=1)[1]
    assert "/extensions/.local/lib/python3.13/site-packages/topstoc_native/" in native_file
    maps = out.split("MAPS", 1)[1]
    # TetGen is linked into the module; Blender itself may load the system's libgomp, the
    # module loads none of its own.
    assert not mapped(maps, "libtet"), mapped(maps, "libtet")
    assert not [p for p in mapped(maps, "libgomp") if "site-packages" in p], mapped(maps, "libgomp")


def test_legacy_zip_installs_in_debian_blender_3_4(tmp_path):
    """The legacy add-on zip (module built on this host) in Debian 12's Blender 3.4."""
    blender = shutil.which("blender") or pytest.skip("no Blender on this host")
    zip_file = ROOT / "build" / "dist" / "topstoc-addon.zip"
    # Always packed anew: a zip left from an older checkout state would test old sources.
    subprocess.run(["cmake", "--build", str(ROOT / "build"), "--target", "addon_zip"], check=True,
                   capture_output=True)
    (tmp_path / "run.py").write_text(BLENDER_SCRIPT)
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "LANG": "C.UTF-8"}
    done = subprocess.run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                           str(tmp_path / "run.py"), "--", str(zip_file), "topstoc", str(MESH)],
                          capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    check_blender_result(done.stdout)
    native_file = next(l for l in done.stdout.splitlines() if l.startswith("NATIVE")).split(maxsplit=1)[1]
    assert native_file.startswith(str(tmp_path / ".config" / "blender")), native_file


def check_blender_result(out: str) -> None:
    """The RESULT line: Guided Decimate made a new closed genus-2 triangle mesh at the ratio."""
    line = next(l for l in out.splitlines() if l.startswith("RESULT")).split()
    status, name = line[1], line[2]
    v, e, f = map(int, line[3:])
    source = topstoc.read_mesh(MESH)  # 315 vertices, genus 2
    assert status == "FINISHED" and name == "eight_TopStoc"
    assert abs(v - 0.3 * len(source.vertices)) <= 1
    assert 2 * e == 3 * f  # closed, every face a triangle
    assert v - e + f == -2  # genus 2 kept (Euler characteristic 2 - 2g)
