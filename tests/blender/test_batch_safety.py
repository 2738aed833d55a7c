"""The Blender batch never writes into a folder it reads inputs from, says one line for an output
that is a file, and writes a symlinked output through (docs/design.md §6.1)."""

import json
import os
import sys

import bpy
import pytest

from conftest import DATA, PACKAGE
from launch import background
from test_batch import MAKE_SCENE

sys.path.insert(0, str(DATA.parent))
import meshgen  # noqa: E402


def batch(*args, timeout=300):
    return background(PACKAGE / "batch.py", *args, timeout=timeout)


def _ring(ts, path):
    path.parent.mkdir(parents=True, exist_ok=True)
    v, f = meshgen.torus(24, 12)
    ts.core.api.io.write_mesh(path, ts.core.api.io.MeshData(vertices=v, triangles=f))
    return path


def _one_error_line(done, *fragments):
    assert done.returncode == 1, done.stdout + done.stderr
    [line] = [line for line in done.stderr.splitlines() if line.startswith("topstoc batch")]
    assert line.startswith("topstoc batch: error: ")
    for fragment in fragments:
        assert fragment in line, line
    assert "Traceback" not in done.stderr and "Errno" not in done.stderr
    assert "topstoc batch: 0 done" not in done.stdout  # refused before any work


def test_outputs_into_an_input_folder_are_refused(ts, tmp_path):
    ring = _ring(ts, tmp_path / "D" / "ring.obj")
    before = ring.read_bytes()
    _one_error_line(batch("--input", ring, "--output", tmp_path / "D", "--ratio", "0.5"),
                    f"the input {ring} lies inside --output {tmp_path / 'D'}")
    _one_error_line(batch("--input", tmp_path / "D", "--output", tmp_path / "D" / "lods", "--ratio", "0.5"),
                    f"--output {tmp_path / 'D' / 'lods'} lies inside the input folder {tmp_path / 'D'}")
    # `--input D/*` after a first run into D/lods names the LOD folder too
    (tmp_path / "D" / "lods").mkdir()
    _one_error_line(batch("--input", ring, tmp_path / "D" / "lods", "--output", tmp_path / "D" / "lods",
                          "--ratio", "0.5"), "is the input folder")
    assert ring.read_bytes() == before
    assert sorted(os.listdir(tmp_path / "D")) == ["lods", "ring.obj"] and not os.listdir(tmp_path / "D" / "lods")


def test_output_naming_a_file_is_one_line(ts, tmp_path):
    ring = _ring(ts, tmp_path / "in" / "ring.obj")
    (tmp_path / "afile").write_text("not a folder")
    _one_error_line(batch("--input", ring, "--output", tmp_path / "afile", "--ratio", "0.5"),
                    f"--output {tmp_path / 'afile'}: is a file, not a folder")
    assert (tmp_path / "afile").read_text() == "not a folder"


@pytest.fixture
def blend_file(ts, scene, tmp_path):
    path = tmp_path / "scene.blend"
    done = background(expr=MAKE_SCENE.format(tests=str(DATA.parent), path=str(path)), timeout=120)
    assert done.returncode == 0 and path.exists(), done.stdout[-2000:] + done.stderr[-2000:]
    return path


def test_symlinked_scene_output_is_written_through(ts, blend_file, tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "kept").mkdir()
    target = tmp_path / "kept" / "scene_lowpoly.blend"
    target.write_bytes(b"an older version")
    os.symlink(target, tmp_path / "out" / "scene.blend")
    done = batch("--input", blend_file, "--output", tmp_path / "out", "--vertices", "100", "--objects", "Ring")
    assert done.returncode == 0, done.stdout + done.stderr
    assert os.readlink(tmp_path / "out" / "scene.blend") == str(target)  # the link kept
    assert sorted(os.listdir(tmp_path / "out")) == ["scene.blend"]
    assert sorted(os.listdir(tmp_path / "kept")) == ["scene_lowpoly.blend"]
    try:
        bpy.ops.wm.open_mainfile(filepath=str(target))
    except RuntimeError as error:
        pytest.skip(f"this Blender cannot read the batch Blender's file: {error}")
    assert len(bpy.data.objects["Ring"].data.vertices) == 100


def test_a_file_name_that_is_not_utf8_fails_that_input_only(ts, tmp_path):
    ring = _ring(ts, tmp_path / "in" / "ring.obj")
    bad = os.path.join(os.fsencode(tmp_path / "in"), b"caf\xe9.obj")
    with open(bad, "wb") as stream:
        stream.write(ring.read_bytes())
    report = tmp_path / "report.json"
    done = batch("--input", os.fsdecode(bad), ring, "--output", tmp_path / "out", "--ratio", "0.5", "--json", report)
    assert done.returncode == 1, done.stdout + done.stderr
    shown = f"{tmp_path}/in/caf\\xe9.obj"
    assert f"topstoc batch [1/2] {shown}: FAILED: {shown}: the file name is not valid UTF-8" in done.stderr
    assert "Traceback" not in done.stderr and "topstoc batch: 1 done, 1 failed" in done.stdout
    data = json.loads(report.read_text())
    assert [f["input"] for f in data["failures"]] == [shown]
    assert [r["vertices_out"] for r in data["results"]] == [144]
