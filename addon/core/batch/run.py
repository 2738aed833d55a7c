"""Running batch assets: one task per asset, serially or on a Dask cluster.

``run_asset`` is the task. Mesh files are decimated in the worker's own process
(topstoc.core.batch.mesh_asset), or with --bake-normals as Blender formats are; Blender formats (.blend, glTF/GLB, FBX, USD) run one Blender per
asset: ``blender -b`` or a Python with PyPI's ``bpy`` (``--blender``), which runs the add-on's
batch (topstoc.blender.batch) and writes its files atomically. A task never raises for a bad
asset: it returns a failure record, so the other assets go on and Dask does not retry a
deterministic failure. A worker that dies (killed, out of memory) is a different matter: Dask
reschedules its tasks on the other workers; the outputs are written to temporary names and
renamed, so a killed task leaves no half-written output, and its Blender child dies with it
(topstoc.core.batch.child_process).
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import time
import traceback
import warnings

from ..support import atomic
from . import settings as batch_settings, child_process
from ..support.atomic import pid_alive
from ..support.errors import TopStocError, one_line, shown_path

MESH_EXTENSIONS = (".obj", ".ply", ".off", ".stl")
COMPRESSED = (".gz", ".bz2")


def asset_kind(path: str):
    """"mesh" for OBJ/PLY/OFF/STL (optionally compressed), "blender" for Blender's formats, else None."""
    name = os.fspath(path).lower()
    for suffix in COMPRESSED:
        if name.endswith(suffix):
            name = name[:-len(suffix)]
    ext = os.path.splitext(name)[1]
    if ext in MESH_EXTENSIONS:
        return "mesh"
    if ext[1:] in batch_settings.BLENDER_FORMATS:
        return "blender"
    return None


def find_inputs(paths) -> list:
    """Files named, and the supported files under folders named (sorted), in order, no repeats."""
    found, seen = [], set()
    for path in paths:
        path = os.fspath(path)
        if os.path.isdir(path):
            names = sorted(os.path.join(root, name) for root, _, files in os.walk(path) for name in files
                           if asset_kind(name) is not None)
        elif os.path.exists(path):
            names = [path]
        else:
            raise FileNotFoundError(f"{path}: no such file or folder")
        for name in names:
            if os.path.abspath(name) not in seen:
                seen.add(os.path.abspath(name))
                found.append(name)
    return found


def utf8_name(path) -> bool:
    """Whether a file name is valid UTF-8 (reports, manifests and Dask keys need text)."""
    try:
        os.fspath(path).encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def misnamed_failure(path) -> dict:
    """The report's failure of an input whose name is not valid UTF-8 (shown with its bytes escaped)."""
    shown = shown_path(path)
    return {"input": shown, "message": f"{shown}: the file name is not valid UTF-8; rename the file"}


def write_report(path: str, report: dict) -> None:
    """Writes a batch report atomically; when that fails, an earlier run's report there is removed
    too, so that no stale report passes for this run's."""
    text = json.dumps(report, indent=2, default=lambda v: v.tolist() if hasattr(v, "tolist") else str(v))
    atomic.write_text(path, text, discard_old=True)


# The topstoc package's folder (this file is topstoc/core/batch/run.py).
_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def package_root() -> str:
    """The folder holding the topstoc package (put on the Blender subprocess's sys.path)."""
    return os.path.dirname(_PACKAGE_DIR)


def blender_command(blender: str) -> list:
    """The command that runs the add-on's batch with ``blender``: a Blender executable, or a Python
    interpreter that has PyPI's ``bpy`` (its name starts with "python")."""
    package = os.path.basename(_PACKAGE_DIR)
    if os.path.basename(blender).startswith("python"):
        # os._exit, not sys.exit: PyPI's bpy 4.5 deadlocks in interpreter shutdown after a batch
        # (outputs already written atomically; the exit status is what counts).
        code = (f"import os, sys; sys.path.insert(0, {package_root()!r}); "
                f"from {package}.blender.batch import main; status = main(sys.argv[1:]); "
                f"sys.stdout.flush(); sys.stderr.flush(); os._exit(int(status or 0))")
        return [blender, "-c", code]
    script = os.path.join(package_root(), package, "batch.py")
    return [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", script, "--"]


def find_blender(blender: str = None) -> str:
    """``blender`` itself, or the Blender on PATH; ValueError when there is none."""
    found = blender or os.environ.get("TOPSTOC_BLENDER") or shutil.which("blender")
    if not found:
        raise TopStocError("Blender formats (.blend, glTF, FBX, USD) need a Blender: install one (blender on PATH), "
                           "or pass --blender /path/to/blender or --blender /venv/bin/python (with PyPI's bpy)")
    return found


def run_blender_asset(path: str, out_dir: str, settings: dict, blender: str) -> dict:
    """One Blender-format asset through a Blender subprocess; its report entry."""
    # The scratch folder names its owner: a killed worker cannot remove it, the next batch does
    # (remove_orphaned_scratch).
    with tempfile.TemporaryDirectory(prefix=f"{SCRATCH_PREFIX}{os.getpid()}-") as scratch:
        report = os.path.join(scratch, "report.json")
        command = blender_command(blender) + ["--input", os.path.abspath(path), "--output", os.path.abspath(out_dir),
                                              "--json", report, *batch_settings.to_argv(settings)]
        env = dict(os.environ)
        env.pop("PYTHONPATH", None)  # the subprocess finds the package through the path given above
        # The Blender child dies with this worker: a killed worker's task is rerun elsewhere,
        # and its Blender must not go on as an orphan.
        done = child_process.run(command, capture_output=True, text=True, env=env, cwd=scratch)
        if not os.path.exists(report):
            tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
            raise TopStocError(f"Blender exited with code {done.returncode} and no report: {' | '.join(tail)}")
        with open(report) as stream:
            data = json.load(stream)
    if data["failures"]:
        raise TopStocError(data["failures"][0]["message"])
    entry = data["results"][0]
    entry["input"] = os.fspath(path)
    return entry


def run_asset(path: str, out_dir: str, settings: dict, blender: str = None) -> dict:
    """The batch task: ``{"status": "done", "entry": ...}`` or ``{"status": "failed", "message": ...}``."""
    started = time.perf_counter()
    # Warnings travel back with the outcome (a Dask worker's stderr would print them in Python's
    # file:line format, across the batch's progress bar); the batch prints them one line each.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            kind = asset_kind(path)
            if kind == "mesh" and settings.get("bake_normals"):  # the maps need Blender's bake and exporter
                from .mesh_asset import check_bakeable

                check_bakeable(path, settings)
                entry = run_blender_asset(path, out_dir, settings, find_blender(blender))
            elif kind == "mesh":
                from .mesh_asset import decimate_mesh_file

                entry = decimate_mesh_file(path, out_dir, settings)
            elif kind == "blender":
                entry = run_blender_asset(path, out_dir, settings, find_blender(blender))
            else:
                raise TopStocError(f"{path}: not a supported asset (mesh files {', '.join(MESH_EXTENSIONS)}, "
                                   f"or {', '.join('.' + f for f in batch_settings.BLENDER_FORMATS)})")
        except Exception as error:  # one broken asset must not stop the batch
            message = one_line(error)
            if not isinstance(error, (ValueError, OSError, RuntimeError)):
                message += " (" + traceback.format_exc().strip().splitlines()[-1] + ")"
            outcome = {"status": "failed", "input": os.fspath(path), "message": message}
        else:
            outcome = {"status": "done", "input": os.fspath(path), "entry": entry}
    said = list(dict.fromkeys(str(w.message) for w in caught))  # once each, in order
    if said:
        outcome["warnings"] = said
        if "entry" in outcome:
            outcome["entry"]["warnings"] = said
    return {**outcome, "wall_seconds": time.perf_counter() - started, "pid": os.getpid()}


def run_serial(tasks, out_dir, settings, blender, on_result) -> None:
    """Runs (index, path) tasks one after another in this process."""
    for index, path in tasks:
        on_result(index, run_asset(path, out_dir, settings, blender))


def _local_cluster(workers: int):
    from distributed import LocalCluster

    threads = str(max(1, (os.cpu_count() or 1) // workers))  # the engine's OpenMP threads per worker
    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                        env={"OMP_NUM_THREADS": threads}, silence_logs=40)


def package_version() -> tuple:
    """This topstoc's version, where it runs (called on the scheduler and the workers)."""
    from ... import bl_info

    return tuple(bl_info["version"])


def check_cluster(client) -> None:
    """TopStocError unless the scheduler and every worker run this topstoc: Dask unpickles the
    tasks on the scheduler too, and a machine without it would fail every asset one by one."""
    here = package_version()
    for where, call in (("the scheduler", client.run_on_scheduler), ("a worker", client.run)):
        try:
            found = call(package_version)
        except Exception as error:  # the remote side's import error, in whatever wrapping
            reason = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
            raise TopStocError(f"{where} of {client.scheduler.address} cannot import topstoc ({reason}): every "
                               "machine of the cluster, the scheduler's too, needs the same topstoc "
                               "(pip install of the same wheel, or PYTHONPATH to the same build)") from None
        versions = set(found.values()) if isinstance(found, dict) else {found}
        if versions != {here}:
            raise TopStocError(f"{where} runs topstoc {' / '.join('.'.join(map(str, v)) for v in sorted(versions))}, "
                               f"this machine {'.'.join(map(str, here))}: install the same version everywhere")


def run_dask(tasks, out_dir, settings, blender, on_result, *, workers: int = 0, scheduler: str = None,
             on_start=None) -> None:
    """Runs (index, path) tasks on a Dask cluster: ``scheduler`` (tcp://HOST:PORT) or a local
    cluster of ``workers`` processes. ``on_start(client)`` is called once the workers are up."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise TopStocError('the Dask runner needs Dask: pip install "topstoc[cluster]" '
                           "(or run serially with --workers 0)") from None
    cluster = None if scheduler else _local_cluster(workers)
    try:
        with Client(scheduler or cluster) as client:
            if scheduler:
                check_cluster(client)
            if on_start is not None:
                on_start(client)
            futures = {}
            for index, path in tasks:
                # Absolute paths: a worker on another machine does not run in this folder.
                future = client.submit(run_asset, os.path.abspath(path), os.path.abspath(out_dir), settings, blender,
                                       key=f"topstoc-batch-{index}-{os.path.basename(path)}", pure=False)
                futures[future] = (index, path)
            for future in as_completed(futures):
                index, path = futures[future]
                try:
                    outcome = future.result()
                except Exception as error:  # e.g. KilledWorker: the asset killed several workers
                    outcome = {"status": "failed", "input": path,
                               "message": f"{type(error).__name__}: {str(error).splitlines()[0] if str(error) else ''}"}
                outcome["input"] = path   # the report names inputs as given, whatever the runner
                if "entry" in outcome:
                    outcome["entry"]["input"] = path
                on_result(index, outcome)
    finally:
        if cluster is not None:
            cluster.close()


SCRATCH_PREFIX = "topstoc-batch-"


def remove_orphaned_scratch(folder: str = None) -> int:
    """Removes ``topstoc-batch-<pid>-*`` scratch folders (in the temporary folder) whose process
    is gone: what a killed worker's Blender task left. Returns how many."""
    folder = folder or tempfile.gettempdir()
    removed = 0
    try:
        names = os.listdir(folder)
    except OSError:
        return 0
    for name in names:
        if not name.startswith(SCRATCH_PREFIX):
            continue
        pid = name[len(SCRATCH_PREFIX):].split("-", 1)[0]
        if not pid.isdigit() or pid_alive(int(pid)):
            continue
        shutil.rmtree(os.path.join(folder, name), ignore_errors=True)
        removed += 1
    return removed


def remove_stale_temporaries(outputs) -> int:
    """Removes what a killed task left next to ``outputs``: ``<name>.tmp<pid>`` files (mesh
    files) and ``.topstoc-partial-<name>-*`` scratch folders (Blender formats); returns how many."""
    removed = 0
    for output in outputs:
        folder, name = os.path.split(output)
        try:
            names = os.listdir(folder or ".")
        except OSError:
            continue
        for other in names:
            stale = os.path.join(folder, other)
            try:
                if other.startswith(name + ".tmp"):
                    os.remove(stale)
                elif other.startswith(f".topstoc-partial-{name}-") and os.path.isdir(stale):
                    shutil.rmtree(stale)
                else:
                    continue
                removed += 1
            except OSError:
                pass
    return removed
