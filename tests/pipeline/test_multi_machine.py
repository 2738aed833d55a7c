"""``topstoc batch --scheduler tcp://…`` on a cluster of several machines, as docs/pipelines.md sets
it up: ``dask scheduler`` on a head node, ``dask worker tcp://HEAD:8786`` on two other nodes, the
batch started from a fourth place, inputs and outputs in a shared folder. The machines are Linux
network namespaces on this host (own network stack and address each, joined by a bridge; the
file system is shared as NFS would share it), so this needs root; it is skipped otherwise.
The outputs must equal the serial batch byte for byte, and the work must have been done by the
worker processes of both nodes. A scheduler or worker without topstoc is a clear error (plain
processes on this host).
"""

import contextlib
import os
import pathlib
import shutil
import signal
import subprocess
import sys

import pytest

from assets import make_assets
from batch_runs import batch, manifest, outputs, report
from conftest import BUILD

pytest.importorskip("distributed")

import netns  # noqa: E402

ASSETS = 20
TARGET = ("--ratio", "0.5")
PORT = 8786
NODES = ("node1", "node2")


def _dask():
    return shutil.which("dask", path=os.path.dirname(sys.executable))


def _skip_reason():
    if not sys.platform.startswith("linux"):
        return "network namespaces are Linux's"
    if os.geteuid() != 0:
        return "needs root (ip netns add, veth pairs, a bridge)"
    if shutil.which("ip") is None:
        return "needs iproute2's ip"
    if _dask() is None:
        return f"no dask command next to {sys.executable}"
    probe = f"{netns.PREFIX}{os.getpid():x}probe"
    done = subprocess.run(["ip", "netns", "add", probe], capture_output=True, text=True)
    subprocess.run(["ip", "netns", "del", probe], capture_output=True)
    if done.returncode != 0:
        return f"cannot create a network namespace: {done.stderr.strip()}"
    return None


@contextlib.contextmanager
def _teardown_on_sigterm():
    """The test command's timeout sends SIGTERM: turn it into KeyboardInterrupt, so that the
    fixture's teardown (kill the processes, delete the namespaces) still runs."""
    def interrupt(signum, frame):
        raise KeyboardInterrupt(f"signal {signum}")
    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _logs(folder) -> str:
    return "".join(f"\n--- {p.name}\n" + p.read_text(errors="replace")[-3000:] for p in sorted(folder.glob("*.log")))


@pytest.fixture
def cluster(tmp_path):
    """A Dask scheduler on "head" and one worker process on each of two nodes:
    (network, scheduler address, the scheduler's view of its workers, log folder)."""
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    logs = tmp_path / "logs"
    logs.mkdir()
    dask = _dask()
    # Every machine has the same topstoc (here: PYTHONPATH to the build under test) and runs from
    # its own folder, not the one the batch is started from.
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"), OMP_NUM_THREADS="1")
    with _teardown_on_sigterm(), netns.Network(("head",) + NODES) as net:
        head = net.address("head")
        address = f"tcp://{head}:{PORT}"
        with open(logs / "scheduler.log", "w") as log:
            net.start("head", [dask, "scheduler", "--host", head, "--port", str(PORT), "--no-dashboard"],
                      cwd="/", env=env, stdout=log, stderr=subprocess.STDOUT)
        for node in NODES:
            with open(logs / f"{node}.log", "w") as log:
                net.start(node, [dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
                                 "--name", node], cwd="/", env=env, stdout=log, stderr=subprocess.STDOUT)
        from distributed import Client
        try:
            with Client(address, timeout="60s") as client:
                client.wait_for_workers(len(NODES), timeout=120)
                workers = client.scheduler_info()["workers"]
        except Exception as error:
            raise AssertionError(f"the cluster did not come up: {error}{_logs(logs)}") from error
        yield net, address, workers, logs
    assert net.leftovers() == [], "namespaces or links left after the test"
    assert not any(process.poll() is None for process in net.processes)


def test_batch_on_a_scheduler_and_workers_on_other_machines(cluster, tmp_path):
    net, address, workers, logs = cluster
    assert sorted(info["host"] for info in workers.values()) == [net.address(node) for node in NODES]
    shared = tmp_path / "shared"
    library = make_assets(shared / "assets", ASSETS, bases=("icosphere", "torus", "fandisk"), levels=(0,))[0].parent
    serial = shared / "serial"
    done = batch("--input", library, "--output", serial, *TARGET, "--workers", 0)
    assert done.returncode == 0, done.stderr

    # Started from the host (a fifth address), with relative paths: the workers run elsewhere.
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    done = subprocess.run([sys.executable, "-m", "topstoc", "batch", "--input", "assets", "--output", "lods", *TARGET,
                           "--scheduler", address, "--progress", "lines"],
                          cwd=shared, capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr + _logs(logs)
    assert f"on {address}, 2 workers" in done.stdout
    out = shared / "lods"
    assert outputs(out) == outputs(serial) and len(outputs(out)) == ASSETS
    data = report(out)
    assert data["runner"]["scheduler"] == address and len(data["results"]) == ASSETS and not data["failures"]
    assert [pathlib.Path(r["input"]).name for r in data["results"]] == [p.name for p in sorted(library.iterdir())]
    # Every asset was decimated by a worker process on node1 or node2, and both nodes worked.
    done_by = {record["worker_pid"] for record in manifest(out)}
    on_node = {node: net.pids(node) for node in NODES}
    assert done_by <= on_node["node1"] | on_node["node2"], (done_by, on_node)
    assert all(done_by & pids for pids in on_node.values()), (done_by, on_node)


@pytest.mark.parametrize("missing", ["scheduler", "worker"])
def test_a_machine_without_topstoc_is_a_clear_error(missing, tmp_path):
    """A scheduler or worker that cannot import topstoc stops the batch at the start with one
    clear line (not a cryptic failure per asset). Plain processes on this host: no root needed."""
    dask = _dask()
    if dask is None:
        pytest.skip(f"no dask command next to {sys.executable}")
    with_topstoc = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    without = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    if subprocess.run([sys.executable, "-c", "import topstoc"], env=without, cwd="/", capture_output=True).returncode == 0:
        pytest.skip(f"{sys.executable} imports topstoc without PYTHONPATH")
    address_file = tmp_path / "scheduler.json"
    started = []
    try:
        for role, command in (("scheduler", [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"]),
                              ("worker", [dask, "worker", "--nworkers", "1", "--nthreads", "1", "--no-dashboard"])):
            with open(tmp_path / f"{role}.log", "w") as log:
                started.append(subprocess.Popen(
                    [*command, "--scheduler-file", str(address_file)], cwd="/", start_new_session=True,
                    env=without if role == missing else with_topstoc, stdout=log, stderr=subprocess.STDOUT))
        from distributed import Client
        with Client(scheduler_file=str(address_file), timeout="60s") as client:
            client.wait_for_workers(1, timeout=120)
            address = client.scheduler.address
        inputs = make_assets(tmp_path / "assets", 3, bases=("torus",), levels=(0,))[0].parent
        done = batch("--input", inputs, "--output", tmp_path / "out", *TARGET, "--scheduler", address)
    finally:
        for process in started:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert done.returncode == 1
    [line] = done.stderr.strip().splitlines()
    where = "the scheduler" if missing == "scheduler" else "a worker"
    assert line.startswith(f"topstoc batch: error: {where} of {address} cannot import topstoc"), line
    assert "the same topstoc" in line
    assert outputs(tmp_path / "out") == {}
