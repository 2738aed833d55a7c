"""``topstoc batch`` at scale: a Dask LocalCluster equals the serial batch byte for byte, resume,
failures, a worker killed by its PID, and the Open Job Description template under ``openjd run``.

Needs dask.distributed (and openjd-cli for the template): scripts/test.sh runs this folder in
the venv it manages under ${TOPSTOC_CACHE:-/var/cache/topstoc}/venv-pipeline.
"""

import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys

import pytest

from assets import make_assets
from batch_runs import batch, leftovers, outputs, ran, report
from conftest import BUILD, ROOT

pytest.importorskip("distributed")

ASSETS = 50
TARGET = ("--ratio", "0.5")


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    return make_assets(tmp_path_factory.mktemp("library"), ASSETS, bases=("icosphere", "torus"), levels=(0,))


@pytest.fixture(scope="module")
def serial(library, tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    done = batch("--input", library[0].parent, "--output", out, *TARGET, "--workers", 0)
    assert done.returncode == 0, done.stderr
    return out


def test_local_cluster_equals_serial_byte_for_byte(library, serial, tmp_path):
    done = batch("--input", library[0].parent, "--output", tmp_path, *TARGET, "--workers", 2)
    assert done.returncode == 0, done.stderr
    assert "2 workers (pids" in done.stdout
    expected = outputs(serial)
    assert len(expected) == ASSETS
    assert outputs(tmp_path) == expected
    data = report(tmp_path)
    assert len(data["results"]) == ASSETS and not data["failures"]
    assert [r["input"] for r in data["results"]] == [str(p) for p in library]   # input order
    assert len({r["worker_pid"] for r in map(json.loads, (tmp_path / "topstoc-manifest.jsonl").open())}) == 2
    assert done.stdout.count("topstoc batch [") == ASSETS
    for entry in data["results"]:
        [lod] = entry["lods"]
        assert lod["hausdorff"] > 0 and lod["vertices"] < entry["vertices_in"]


def test_resume_skips_done_work(library, serial, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(serial, out)
    before = {name: (out / name).stat().st_mtime_ns for name in outputs(out)}
    done = batch("--input", library[0].parent, "--output", out, *TARGET, "--workers", 0)
    assert done.returncode == 0, done.stderr
    data = report(out)
    assert len(data["skipped"]) == ASSETS and not ran(data)
    # the figures of the earlier run stay in the report
    assert [{k: v for k, v in r.items() if k != "resumed"} for r in data["results"]] == report(serial)["results"]
    assert {name: (out / name).stat().st_mtime_ns for name in outputs(out)} == before
    # An edited input, a deleted output and other settings make exactly those run again.
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    for path in library[:10]:
        shutil.copy(path, inputs)
    rerun = tmp_path / "rerun"
    assert batch("--input", inputs, "--output", rerun, *TARGET, "--workers", 0).returncode == 0
    # A run cut while writing the manifest's last line: that asset runs again.
    manifest = rerun / "topstoc-manifest.jsonl"
    text = manifest.read_text()
    manifest.write_text(text[:-40])
    done = batch("--input", inputs, "--output", rerun, *TARGET, "--workers", 0)
    assert len(ran(report(rerun))) == 1 and len(report(rerun)["skipped"]) == 9
    edited = sorted(inputs.iterdir())[3]
    edited.write_bytes(edited.read_bytes() + b"\n")
    deleted = sorted(outputs(rerun))[7]
    (rerun / deleted).unlink()
    done = batch("--input", inputs, "--output", rerun, *TARGET, "--workers", 0)
    assert done.returncode == 0, done.stderr
    data = report(rerun)
    assert sorted(pathlib.Path(r["input"]).name for r in ran(data)) == sorted([edited.name, deleted])
    assert len(data["results"]) == 10
    assert len(data["skipped"]) == 8
    expected = {name: data for name, data in outputs(serial).items() if name in {p.name for p in library[:10]}}
    assert outputs(rerun) == expected   # the edit is a trailing newline: the same mesh
    done = batch("--input", inputs, "--output", rerun, "--ratio", "0.4", "--workers", 0)
    assert len(ran(report(rerun))) == 10


def test_a_failing_asset_is_reported_and_the_others_go_on(library, tmp_path):
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    for path in library[:6]:
        shutil.copy(path, inputs)
    (inputs / "broken.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")   # truncated
    (inputs / "nofaces.obj").write_text("v 0 0 0\nv 1 0 0\n")
    out = tmp_path / "out"
    done = batch("--input", inputs, "--output", out, *TARGET, "--workers", 2)
    assert done.returncode == 1
    data = report(out)
    assert sorted(pathlib.Path(f["input"]).name for f in data["failures"]) == ["broken.off", "nofaces.obj"]
    assert all(f["message"] for f in data["failures"])
    assert len(data["results"]) == 6 and "FAILED" in done.stderr
    # The failures are not recorded as done: a rerun tries them again, and only them.
    done = batch("--input", inputs, "--output", out, *TARGET, "--workers", 0)
    data = report(out)
    assert len(data["skipped"]) == 6 and len(data["failures"]) == 2


def test_a_killed_worker_loses_nothing(library, serial, tmp_path):
    """SIGKILL one of two worker processes mid-run: Dask reruns its tasks on the other (and the
    nanny's replacement); every output is complete and equals the serial batch."""
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    command = [sys.executable, "-m", "topstoc", "batch", "--input", str(library[0].parent), "--output",
               str(tmp_path), *TARGET, "--workers", "2", "--progress", "lines"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    pids, progress, killed, lines = [], 0, None, []
    try:
        for line in process.stdout:
            lines.append(line)
            if "workers (pids" in line:
                pids = [int(p) for p in line.split("(pids ")[1].split(")")[0].split()]
            elif line.startswith("topstoc batch ["):
                progress += 1
                if progress == 5 and killed is None:
                    killed = pids[0]
                    os.kill(killed, signal.SIGKILL)
                    killed_at = progress
        rest, errors = process.communicate(timeout=600)
    finally:
        if process.poll() is None:
            process.kill()
    assert killed is not None, "".join(lines)
    assert process.returncode == 0, errors
    assert killed_at < ASSETS and progress == ASSETS
    assert outputs(tmp_path) == outputs(serial)
    assert leftovers(tmp_path) == []
    data = report(tmp_path)
    assert len(data["results"]) == ASSETS and not data["failures"]


def test_missing_dask_is_a_clear_message(tmp_path, library):
    python = "/usr/bin/python3"
    probe = subprocess.run([python, "-c", "import distributed"], capture_output=True)
    if probe.returncode == 0:
        pytest.skip(f"{python} has dask.distributed")
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    done = subprocess.run([python, "-m", "topstoc", "batch", "--input", str(library[0]), "--output", str(tmp_path),
                           *TARGET, "--workers", "2"], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 1
    assert 'pip install "topstoc[cluster]"' in done.stderr and "--workers 0" in done.stderr
    done = subprocess.run([python, "-m", "topstoc", "batch", "--input", str(library[0]), "--output", str(tmp_path),
                           *TARGET, "--workers", "0"], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr


def test_openjd_template_runs_the_chunks(library, serial, tmp_path):
    openjd = shutil.which("openjd", path=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""))
    if openjd is None:
        pytest.skip("openjd-cli is not installed")
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    for path in library[:10]:
        shutil.copy(path, inputs)
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    done = subprocess.run([openjd, "run", str(ROOT / "farm" / "openjd" / "topstoc-batch.yaml"),
                           "-p", f"InputFolder={inputs}", "-p", f"OutputFolder={out}", "-p", "ChunkCount=3",
                           "-p", f"Topstoc={sys.executable} -m topstoc", "-p", "TargetArgs=" + " ".join(TARGET)],
                          capture_output=True, text=True, env=env, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "Chunks run: 3" in done.stdout or "Tasks run: 3" in done.stdout, done.stdout[-2000:]
    expected = {name: data for name, data in outputs(serial).items() if name in {p.name for p in library[:10]}}
    assert outputs(out) == expected
    reports = [report(out, f"topstoc-report-chunk{i}of3.json") for i in (1, 2, 3)]
    assert sorted(len(r["results"]) for r in reports) == [3, 3, 4]


MAKE_BLEND = """
import sys, bpy
sys.path.insert(0, {tests!r})
import meshgen
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
v, f = meshgen.torus(24, 12)
mesh = bpy.data.meshes.new("Ring")
mesh.from_pydata(v.tolist(), [], f.tolist())
bpy.context.scene.collection.objects.link(bpy.data.objects.new("Ring", mesh))
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""


def test_blender_assets_run_a_blender_per_task(library, tmp_path):
    blender = shutil.which("blender")
    if blender is None:
        pytest.skip("no blender on PATH")
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    scene = inputs / "scene.blend"
    subprocess.run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr",
                    MAKE_BLEND.format(tests=str(ROOT / "tests"), path=str(scene))],
                   check=True, capture_output=True, timeout=300)
    shutil.copy(library[0], inputs)
    out = tmp_path / "out"
    done = batch("--input", inputs, "--output", out, "--ratio", "0.25", "0.1", "--workers", 2, "--blender", blender)
    assert done.returncode == 0, done.stdout + done.stderr
    data = report(out)
    by_name = {pathlib.Path(r["input"]).name: r for r in data["results"]}
    [ring] = by_name["scene.blend"]["objects"]
    assert [lod["object"] for lod in ring["lods"]] == ["Ring_LOD0", "Ring_LOD1"]
    assert all(abs(lod["vertices"] - r * 288) <= 3 for lod, r in zip(ring["lods"], (0.25, 0.1)))
    assert (out / "scene.blend").is_file() and not list(out.glob(".topstoc-partial*"))
    assert len(by_name[library[0].name]["lods"]) == 2


def test_a_workers_warning_prints_one_line_in_the_driver(tmp_path):
    """A Dask worker's warning travels back with the asset's outcome: one line on the driver's
    stderr, not Python's file:line format on the worker's."""
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "old.ply").write_text(
        "ply\nformat ascii 1.0\nCreated by Blender3D 247\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
    done = batch("--input", tmp_path / "in", "--output", tmp_path / "out", "--ratio", "1", "--workers", 1)
    assert done.returncode == 0, done.stderr
    assert "MeshFileWarning" not in done.stderr
    # (Dask may warn about the machine, e.g. a port in use: those lines are its own)
    assert [line for line in done.stderr.splitlines() if "old.ply" in line] == [
        f"topstoc: warning: {tmp_path / 'in' / 'old.ply'}: line 3: skipped unknown PLY header line "
        "'Created by Blender3D 247'"]
