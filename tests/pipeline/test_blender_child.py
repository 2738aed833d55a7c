"""A Dask worker killed (by its PID) while its Blender child decimates a glTF asset: the child dies
with it instead of running on as an orphan, the asset is rerun on another worker, and the
outputs equal the serial batch byte for byte. Runs with Debian's Blender (``blender`` on PATH)
and with PyPI's bpy (the checkout's .venv, or $TOPSTOC_BPY_PYTHON), whichever are there."""

import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import pytest

from batch_runs import Background, alive, batch, leftovers, manifest, outputs, processes, report
from conftest import ROOT

pytest.importorskip("distributed")
pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc; PR_SET_PDEATHSIG")

TARGET = ("--ratio", "0.2")

MAKE_GLB = """
import sys, bpy
sys.path.insert(0, {tests!r})
import meshgen
for name, (nu, nv) in (("big", (768, 384)), ("ring", (48, 24))):
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    v, f = meshgen.torus(nu, nv)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(v.tolist(), [], f.tolist())
    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))  # shared vertices in the glTF
    bpy.context.scene.collection.objects.link(bpy.data.objects.new(name, mesh))
    bpy.ops.export_scene.gltf(filepath={folder!r} + "/" + name + ".glb", export_format="GLB")
"""


def _bpy_python():
    for python in (os.environ.get("TOPSTOC_BPY_PYTHON"), str(ROOT / ".venv" / "bin" / "python")):
        if python and os.access(python, os.X_OK) and subprocess.run(
                [python, "-c", "import bpy"], capture_output=True, timeout=120).returncode == 0:
            return python
    return None


def _runner(kind):
    found = shutil.which("blender") if kind == "blender" else _bpy_python()
    if found is None:
        pytest.skip("no blender on PATH" if kind == "blender" else "no Python with PyPI's bpy (.venv, $TOPSTOC_BPY_PYTHON)")
    return found


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """A 590k-triangle torus (seconds of Blender's time, 3-4 on the fastest machine seen) and two
    small ones, as GLB."""
    blender = shutil.which("blender")
    if blender is None:
        pytest.skip("no blender on PATH to make the glTF assets")
    made = tmp_path_factory.mktemp("made")
    subprocess.run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr",
                    MAKE_GLB.format(tests=str(ROOT / "tests"), folder=str(made))],
                   check=True, capture_output=True, timeout=300)
    folder = tmp_path_factory.mktemp("glb")
    shutil.copy(made / "big.glb", folder / "a_big.glb")   # sorted first: the first task
    for i in range(2):
        shutil.copy(made / "ring.glb", folder / f"b_ring{i}.glb")
    return folder


@pytest.fixture(scope="module")
def serial_runs(library, tmp_path_factory):
    """The serial batch of the library with each runner (made on first use): {kind: folder}."""
    made = {}

    def serial(kind, runner):
        if kind not in made:
            out = tmp_path_factory.mktemp(f"serial-{kind}")
            done = batch("--input", library, "--output", out, *TARGET, "--workers", 0, "--blender", runner)
            assert done.returncode == 0, done.stdout + done.stderr
            made[kind] = out
        return made[kind]
    return serial


def _blender_child(run, asset, parents) -> tuple:
    """Waits until one of ``parents`` runs a Blender on ``asset``; (its pid, the parent's)."""
    deadline = time.monotonic() + 120
    while not (children := {pid: ppid for pid, ppid in processes(asset).items() if ppid in parents}):
        assert time.monotonic() < deadline and run.process.poll() is None, "no Blender child:\n" + run.output()
        time.sleep(0.01)
    [(child, parent)] = children.items()
    return child, parent


def _kill_what_is_left(library):
    for pid in processes(str(library)):   # whatever a failed run left
        os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize("kind", ["blender", "bpy"])
def test_a_killed_workers_blender_child_dies_and_its_asset_is_rerun(kind, library, serial_runs, tmp_path):
    runner = _runner(kind)
    serial = serial_runs(kind, runner)
    big = str(library / "a_big.glb")
    [serial_big] = [entry for entry in report(serial)["results"] if entry["input"] == big]

    out = tmp_path / "cluster"
    run = Background("--input", library, "--output", out, *TARGET, "--workers", 2, "--blender", runner)
    try:
        child, worker = _blender_child(run, big, run.worker_pids())
        seen = time.monotonic()
        time.sleep(0.3)   # the child is under way
        assert alive(child), "the Blender child ended before the worker could be killed:\n" + run.output()
        os.kill(worker, signal.SIGKILL)
        killed = time.monotonic()
        while alive(child) and time.monotonic() - killed < 1.0:
            time.sleep(0.01)
        assert not alive(child), f"the Blender child {child} of killed worker {worker} runs on as an orphan"
        returncode = run.finish()
    finally:
        run.stop()
        _kill_what_is_left(library)
    # The child had work left when it died: it would not have ended by itself that soon.
    assert serial_big["wall_seconds"] > (killed - seen) + 1.0 + 0.5, serial_big["wall_seconds"]
    assert returncode == 0, run.output()
    assert processes(str(library)) == {}   # no Blender or bpy process left for these assets
    assert outputs(out) == outputs(serial) and len(outputs(out)) == 3
    assert leftovers(out) == []
    # the killed task's scratch folder (named after its worker) was removed at the end
    assert not list(pathlib.Path(tempfile.gettempdir()).glob(f"topstoc-batch-{worker}-*"))
    data = report(out)
    assert len(data["results"]) == 3 and not data["failures"]
    [record] = [r for r in manifest(out) if r["input"] == big]
    assert record["status"] == "done" and record["worker_pid"] != worker   # rerun elsewhere


def test_a_killed_batch_leaves_no_worker_or_blender_and_resumes(library, serial_runs, tmp_path):
    """SIGKILL the driving ``topstoc batch`` while a Blender works: its local cluster's workers
    leave (Dask's parent watch) and take their Blender children with them; a rerun finishes the
    job with the outputs of the serial batch and nothing half-written."""
    runner = _runner("blender")
    serial = serial_runs("blender", runner)
    out = tmp_path / "cluster"
    run = Background("--input", library, "--output", out, *TARGET, "--workers", 2, "--blender", runner)
    try:
        workers = run.worker_pids()
        child, _ = _blender_child(run, str(library / "a_big.glb"), workers)
        time.sleep(0.3)
        run.process.kill()
        run.finish()
        deadline = time.monotonic() + 15
        while any(map(alive, workers + [child])) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(map(alive, workers + [child])), "workers or their Blender outlived the killed batch"
        assert processes(str(library)) == {}
    finally:
        run.stop()
        _kill_what_is_left(library)
    done = batch("--input", library, "--output", out, *TARGET, "--workers", 2, "--blender", runner)
    assert done.returncode == 0, done.stdout + done.stderr
    assert outputs(out) == outputs(serial) and leftovers(out) == []
