"""Batch decimation through Blender's command line (docs/design.md §6): exit codes, JSON report,
outputs that really are decimated."""

import importlib
import importlib.util
import json

import bpy
import numpy as np
import pytest

from conftest import DATA, PACKAGE
from launch import background


def batch(*args, timeout=300):
    """The batch command in the Blender under test (see launch.py)."""
    return background(PACKAGE / "batch.py", *args, timeout=timeout)


def has_io(ts):
    return importlib.util.find_spec(ts.__name__ + ".core.api.io") is not None


MAKE_SCENE = """
import sys, bpy
sys.path.insert(0, {tests!r})
import meshgen
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
for name, (v, f) in (("Ball", meshgen.icosphere(3)), ("Ring", meshgen.torus(32, 12))):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(v.tolist(), [], f.tolist())
    bpy.context.scene.collection.objects.link(bpy.data.objects.new(name, mesh))
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""


@pytest.fixture
def blend_file(ts, scene, tmp_path):
    """A .blend with two mesh objects, written by the same Blender that runs the batch."""
    path = tmp_path / "scene.blend"
    done = background(expr=MAKE_SCENE.format(tests=str(DATA.parent), path=str(path)), timeout=120)
    assert done.returncode == 0 and path.exists(), done.stdout[-2000:] + done.stderr[-2000:]
    return path


def _open(path):
    """Opens a batch output in this session (skipped when it was written by a newer Blender)."""
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path))
    except RuntimeError as error:
        pytest.skip(f"this Blender cannot read the batch Blender's file: {error}")


def test_blend_files_and_a_broken_one(ts, blend_file, tmp_path):
    broken = tmp_path / "broken.blend"
    broken.write_text("not a blend file")
    out = tmp_path / "out"
    report = tmp_path / "report.json"
    done = batch("--input", blend_file, broken, "--ratio", "0.25", "--output", out, "--json", report)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "[2/2]" in done.stdout and "FAILED" in done.stderr and "broken.blend" in done.stderr
    data = json.loads(report.read_text())
    assert [f["input"] for f in data["failures"]] == [str(broken)]
    assert data["failures"][0]["message"]
    [result] = data["results"]
    assert result["output"] == str(out / "scene.blend")
    assert {o["object"] for o in result["objects"]} == {"Ball", "Ring"}
    for entry in result["objects"]:
        assert abs(entry["vertices_out"] - 0.25 * entry["vertices_in"]) <= 0.01 * entry["vertices_in"] + 1
    # The saved file really holds the decimated meshes.
    _open(out / "scene.blend")
    counts = {o.name: len(o.data.vertices) for o in bpy.data.objects if o.type == "MESH"}
    assert counts == {o["object"]: o["vertices_out"] for o in result["objects"]}


def test_named_objects_only(ts, blend_file, tmp_path):
    done = batch("--input", blend_file, "--vertices", "100", "--objects", "Ring", "--output", tmp_path / "o")
    assert done.returncode == 0, done.stderr
    _open(tmp_path / "o" / "scene.blend")
    assert len(bpy.data.objects["Ring"].data.vertices) == 100
    assert len(bpy.data.objects["Ball"].data.vertices) == 642   # untouched
    done = batch("--input", blend_file, "--ratio", "0.5", "--objects", "Nope", "--output", tmp_path / "p")
    assert done.returncode == 1 and "no object named 'Nope'" in done.stderr


def test_bad_arguments_exit_non_zero(ts, tmp_path):
    done = batch("--input", DATA / "genus0" / "cgal_fandisk.off", "--output", tmp_path)
    assert done.returncode != 0 and "one of the arguments" in done.stderr
    # one line, as topstoc batch prints it, no usage dump
    [line] = [text for text in done.stderr.splitlines() if text.startswith("topstoc batch: error: ")]
    assert "usage:" not in done.stderr and line.endswith("(see 'blender -b --python topstoc/batch.py -- --help')")


def test_mesh_files(ts, tmp_path):
    if not has_io(ts):
        pytest.skip("topstoc.core.api.io is not in this build")
    inputs = [DATA / "genus0" / "cgal_fandisk.off", DATA / "uv_materials" / "spider" / "spider.obj",
              DATA / "open_boundary" / "kivy_suzanne_monkey.obj",
              DATA / "nonmanifold_degenerate" / "openscad_unparseable.stl"]
    out = tmp_path / "out"
    report = tmp_path / "r.json"
    done = batch("--input", *inputs, "--ratio", "0.3", "--output", out, "--json", report)
    assert done.returncode == 1, done.stdout + done.stderr
    data = json.loads(report.read_text())
    assert [f["input"] for f in data["failures"]] == [str(inputs[3])]
    assert len(data["results"]) == 3
    io = importlib.import_module(ts.__name__ + ".core.api.io")
    for entry in data["results"]:
        written = io.read_mesh(entry["output"])
        assert written.num_vertices == entry["vertices_out"] < entry["vertices_in"]
        assert written.num_triangles == entry["triangles_out"]
    spider = io.read_mesh(out / "spider.obj")
    assert spider.corner_uvs is not None and spider.triangle_material is not None



def test_folders_as_topstoc_batch_takes_them(ts, tmp_path):
    """A folder is searched recursively for supported files, as ``topstoc batch`` does."""
    if not has_io(ts):
        pytest.skip("topstoc.core.api.io is not in this build")
    folder = tmp_path / "assets"
    (folder / "sub").mkdir(parents=True)
    for source, target in ((DATA / "genus0" / "cgal_fandisk.off", folder / "fandisk.off"),
                           (DATA / "open_boundary" / "kivy_suzanne_monkey.obj", folder / "sub" / "suzanne.obj")):
        target.write_bytes(source.read_bytes())
    (folder / "notes.txt").write_text("not an asset")
    report = tmp_path / "r.json"
    done = batch("--input", folder, "--ratio", "0.3", "--output", tmp_path / "out", "--json", report)
    assert done.returncode == 0, done.stdout + done.stderr
    data = json.loads(report.read_text())
    assert sorted(e["input"] for e in data["results"]) == [str(folder / "fandisk.off"), str(folder / "sub" / "suzanne.obj")]
    assert (tmp_path / "out" / "fandisk.off").exists() and (tmp_path / "out" / "suzanne.obj").exists()
    missing = batch("--input", tmp_path / "nowhere", "--ratio", "0.3", "--output", tmp_path / "out2")
    assert missing.returncode == 1 and "nowhere: no such file or folder" in missing.stderr


@pytest.mark.heavy
def test_max_error_target(ts, tmp_path):
    if not has_io(ts):
        pytest.skip("needs topstoc.core.api.io")
    source = DATA / "genus0" / "cgal_fandisk.off"
    report = tmp_path / "r.json"
    done = batch("--input", source, "--max-error", "0.5%", "--output", tmp_path / "o", "--json", report)
    assert done.returncode == 0, done.stdout + done.stderr
    [entry] = json.loads(report.read_text())["results"]
    io = importlib.import_module(ts.__name__ + ".core.api.io")
    original = io.read_mesh(source)
    diagonal = float(np.linalg.norm(original.vertices.max(axis=0) - original.vertices.min(axis=0)))
    assert entry["error"] is not None and entry["error"] <= 0.005 * diagonal
    assert entry["vertices_out"] < entry["vertices_in"]
    done = batch("--input", source, "--max-error", "abc", "--output", tmp_path / "p")
    assert done.returncode == 1 and "--max-error must be a number" in done.stderr


def _mirror_gap(vertices, axis=0):
    """Largest distance from a mirrored vertex to the nearest vertex."""
    mirrored = vertices.copy()
    mirrored[:, axis] *= -1
    return np.linalg.norm(vertices[None, :, :] - mirrored[:, None, :], axis=2).min(axis=1).max()


def test_symmetry_in_a_blend_batch(ts, blend_file, tmp_path):
    report = tmp_path / "r.json"
    done = batch("--input", blend_file, "--ratio", "0.2", "--symmetry", "x", "--output", tmp_path / "s",
                 "--json", report)
    assert done.returncode == 0, done.stdout + done.stderr
    [result] = json.loads(report.read_text())["results"]
    assert all(lod["symmetry"] == "X" for entry in result["objects"] for lod in entry["lods"])
    _open(tmp_path / "s" / "scene.blend")
    for name in ("Ball", "Ring"):
        co = np.array([tuple(v.co) for v in bpy.data.objects[name].data.vertices])
        diagonal = np.linalg.norm(co.max(axis=0) - co.min(axis=0))
        assert _mirror_gap(co) <= 1e-5 * diagonal, name
    # the plain batch is not mirror-symmetric, so the check can tell
    done = batch("--input", blend_file, "--ratio", "0.2", "--objects", "Ring", "--output", tmp_path / "p")
    assert done.returncode == 0, done.stdout + done.stderr
    _open(tmp_path / "p" / "scene.blend")
    co = np.array([tuple(v.co) for v in bpy.data.objects["Ring"].data.vertices])
    assert _mirror_gap(co) > 1e-3 * np.linalg.norm(co.max(axis=0) - co.min(axis=0))
