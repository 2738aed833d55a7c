"""Writes survive faults (topstoc.core.support.atomic): a signal or a full disk leaves neither a half-written
file at the final name nor a temporary file; a killed process's temporary files are swept by the
next write to that output; a batch report that cannot be written leaves no stale one behind."""

import errno
import os
import shutil
import signal
import subprocess
import sys

import pytest

import cli
import meshgen
from conftest import BUILD
from topstoc.core.support import atomic
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

# The CLI with the rename held back: it prints the temporary file's name, then waits there for the
# test's signal (the write itself has happened, the rename not yet).
PAUSED_CLI = """
import os, sys, time
real_replace = os.replace
def paused_replace(source, destination):
    print(source, flush=True)
    time.sleep(120)
    real_replace(source, destination)
os.replace = paused_replace
from topstoc.core.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.fixture
def ring(tmp_path):
    v, f = meshgen.torus(48, 24)
    write_mesh(tmp_path / "ring.ply", MeshData(vertices=v, triangles=f))
    return tmp_path / "ring.ply"


@pytest.mark.parametrize("signum, status", [(signal.SIGTERM, -signal.SIGTERM), (signal.SIGINT, 130)])
def test_a_signal_during_the_write_removes_the_temporary_file(ring, tmp_path, signum, status):
    out = tmp_path / "out.ply"
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    # SIGINT back to its default: a suite started in the background (`cmd &`) runs with it ignored.
    child = subprocess.Popen([sys.executable, "-c", PAUSED_CLI, "decimate", str(ring), str(out), "--ratio", "0.5"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        temporary = child.stdout.readline().strip()
        assert temporary == f"{out}.tmp{child.pid}"
        assert os.path.getsize(temporary) > 1000  # written, not yet renamed
        child.send_signal(signum)
        _, stderr = child.communicate(timeout=60)
    finally:
        child.kill()
    assert child.returncode == status, stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ring.ply"]
    if signum == signal.SIGINT:
        assert stderr.strip() == "topstoc decimate: error: interrupted"


def _dead_pid() -> int:
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(done.stdout)


def test_temporary_files_of_dead_processes_are_swept_by_the_next_write(ring, tmp_path):
    """SIGKILL cannot be caught: its temporary file stays until the same output is written again;
    a live process's temporary file (another writer at work) and other names are left alone."""
    dead, alive = _dead_pid(), os.getppid()
    for name in (f"out.ply.tmp{dead}", f"out.ply.tmp{alive}", f"other.ply.tmp{dead}", f"out.ply.tmp{dead}.notes"):
        (tmp_path / name).write_bytes(b"half")
    done = cli.run("decimate", ring, tmp_path / "out.ply", "--ratio", 0.5)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["ring.ply", "out.ply", f"out.ply.tmp{alive}", f"other.ply.tmp{dead}", f"out.ply.tmp{dead}.notes"])


def _disk_full(stream):
    stream.write(b"{\"results\": [")
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_failed_write_leaves_no_temporary_file_and_no_stale_report(tmp_path):
    report = tmp_path / "report.json"
    report.write_text('{"results": ["the previous run"]}')
    with pytest.raises(OSError, match=r"report\.json: cannot write the file \(no space left on device\)$") as caught:
        atomic.write_file(report, _disk_full)
    assert caught.value.errno == errno.ENOSPC and "Errno" not in str(caught.value)
    assert report.read_text() == '{"results": ["the previous run"]}'  # a mesh file keeps its old version
    with pytest.raises(OSError, match="no space left on device.; the earlier file there was removed"):
        atomic.write_file(report, _disk_full, discard_old=True)     # a report must not pass for this run's
    assert list(tmp_path.iterdir()) == []


def _can_mount_tmpfs() -> bool:
    if os.geteuid() != 0 or shutil.which("unshare") is None:
        return False
    done = subprocess.run(["unshare", "-m", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /mnt"], capture_output=True)
    return done.returncode == 0


@pytest.mark.skipif(not _can_mount_tmpfs(), reason="needs root and unshare to mount a private 64 KiB tmpfs")
def test_batch_report_on_a_full_disk(ring, tmp_path):
    """A real ENOSPC: the report goes to a 64 KiB tmpfs (in a private mount namespace) that a
    filler file has filled; the earlier run's report there is removed, no temporary file stays."""
    (tmp_path / "in").mkdir()
    shutil.move(ring, tmp_path / "in" / "ring.ply")
    disk = tmp_path / "disk"
    disk.mkdir()
    script = (f"mount -t tmpfs -o size=64k tmpfs {disk} && echo '{{\"results\": []}}' > {disk}/report.json && "
              f"(head -c 1M /dev/zero > {disk}/filler 2>/dev/null; true) && "
              f"{sys.executable} -m topstoc batch --input {tmp_path}/in --output {tmp_path}/out --ratio 0.5 "
              f"--workers 0 --json {disk}/report.json; echo status $?; ls -a {disk}")
    done = subprocess.run(["unshare", "-m", "sh", "-c", script], capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(BUILD / "python")), timeout=300)
    lines = done.stdout.strip().splitlines()
    assert lines[-4:] == ["status 1", ".", "..", "filler"], done.stdout + done.stderr
    [error] = done.stderr.strip().splitlines()
    assert error == (f"topstoc batch: error: {disk}/report.json: cannot write the file (no space left on device); "
                     "the earlier file there was removed")
    assert read_mesh(tmp_path / "out" / "ring.ply").num_vertices == 1152 // 2  # the asset itself was done

