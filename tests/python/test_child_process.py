"""Children started by ``topstoc.core.batch.child_process.run`` die when the process that started them is
killed (what keeps a killed Dask worker's Blender from running on as an orphan), and the batch
removes what a killed Blender left in the output folder. The real Blender under a Dask worker is
tested in tests/pipeline/test_blender_child.py."""

import os
import pathlib
import signal
import subprocess
import sys
import time
import uuid

import pytest

from conftest import BUILD
from topstoc.core.batch import run as batch_run, child_process

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux only")

STARTER = """
import subprocess, sys
from topstoc.core.batch import child_process
run = child_process.run if sys.argv[1] == "die-with-parent" else subprocess.run
run([sys.executable, "-c", "import time; time.sleep(60)", sys.argv[2]])
"""


def _children(parent: int, marker: str) -> list:
    """Live processes whose parent is ``parent`` and whose command line holds ``marker``."""
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
                command = (entry / "cmdline").read_bytes().decode(errors="replace")
            except OSError:
                continue
            state, ppid = stat.rsplit(")", 1)[1].split()[:2]
            if int(ppid) == parent and marker in command and state != "Z":
                found.append(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    """Running (not gone, not a zombie waiting to be reaped)."""
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _kill_starter(how: str) -> tuple:
    """Starts a Python that starts a sleeping Python with ``how``, SIGKILLs the first once the
    second runs; returns (the sleeper's pid, whether it is still running 2 s later)."""
    marker = uuid.uuid4().hex
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    starter = subprocess.Popen([sys.executable, "-c", STARTER, how, marker], env=env)
    try:
        deadline = time.monotonic() + 30
        while not (children := _children(starter.pid, marker)):
            assert time.monotonic() < deadline and starter.poll() is None, "the child never started"
            time.sleep(0.02)
        [child] = children
        starter.kill()
        starter.wait()
        deadline = time.monotonic() + 2
        while _alive(child) and time.monotonic() < deadline:
            time.sleep(0.02)
        return child, _alive(child)
    finally:
        if starter.poll() is None:
            starter.kill()


def test_the_child_dies_with_its_killed_parent():
    child, alive = _kill_starter("die-with-parent")
    assert not alive, f"process {child} outlived its parent"


def test_without_it_the_child_is_orphaned():
    """The control: a plain subprocess.run child goes on after its parent's SIGKILL (so the test
    above can fail)."""
    child, alive = _kill_starter("plain")
    try:
        assert alive
    finally:
        if alive:
            os.kill(child, signal.SIGKILL)


def test_run_passes_output_and_status_through(tmp_path):
    done = child_process.run([sys.executable, "-c", "import sys; print(sys.stdin.read() == ''); sys.exit(3)"],
                             capture_output=True, text=True, cwd=tmp_path)
    assert (done.returncode, done.stdout) == (3, "True\n")   # no standard input: reads end at once


def test_elsewhere_the_child_is_started_as_before(monkeypatch):
    monkeypatch.setattr(sys, "platform", "darwin")
    assert child_process.die_with_parent() is None
    assert child_process.run([sys.executable, "-c", "print(1)"], capture_output=True, text=True).stdout == "1\n"


def test_stale_temporaries_of_killed_tasks_are_removed(tmp_path):
    out = tmp_path / "out"
    (out / ".topstoc-partial-ring.glb-x1y2").mkdir(parents=True)
    (out / ".topstoc-partial-ring.glb-x1y2" / "ring.glb").write_bytes(b"half")
    (out / "ring.glb").write_bytes(b"done")
    (out / "bunny.obj.tmp123").write_text("half")
    (out / "bunny.obj").write_text("done")
    (out / ".topstoc-partial-other.glb-abcd").mkdir()   # another asset's (maybe still writing)
    (out / "ring.glb.notes").write_text("kept")
    removed = batch_run.remove_stale_temporaries([str(out / "ring.glb"), str(out / "bunny.obj")])
    assert removed == 2
    assert sorted(p.name for p in out.iterdir()) == [".topstoc-partial-other.glb-abcd", "bunny.obj", "ring.glb",
                                                     "ring.glb.notes"]
