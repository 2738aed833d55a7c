"""Batch throughput: assets per minute serially in one Blender, serially without Blender, on a
local Dask cluster with 2 worker processes, and as 2 chunk processes side by side (--chunk, as a
farm runs the OpenJD template), same assets, same run; overhead per asset.

    PATH=/var/cache/topstoc/venv-pipeline/bin:$PATH \\
        /var/cache/topstoc/venv-pipeline/bin/python tests/bench/bench_batch.py [--count 200] [--ratio 0.3]

The assets (the test meshes and synthetic ones at subdivision levels 0 and 1, under random
similarity transforms, OBJ/PLY/OFF) are generated into a temporary folder. Each mode writes its
own output folder; outputs of the three runs must be byte-identical (checked). Overhead per
asset = (wall time x processes - summed per-asset work) / assets: process start-up, reading,
writing, measuring, scheduling (the cluster's start-up included). The JSON report of the cluster
run is printed at the end (--report FILE keeps the whole report); --json FILE writes the figures
(per mode: wall and work seconds, assets per minute, overhead, load average before and after).
"""

import argparse
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))
sys.path.insert(0, str(BUILD / "python"))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine  # noqa: E402

from assets import make_assets  # noqa: E402


def outputs(folder) -> dict:
    return {p.name: p.read_bytes() for p in sorted(pathlib.Path(folder).iterdir())
            if p.is_file() and not p.name.startswith("topstoc-")}


def load() -> float:
    return os.getloadavg()[0]


def timed(command, env) -> tuple:
    """(wall seconds, 1-minute load average before, after)."""
    return timed_side_by_side([command], env)


def timed_side_by_side(commands, env) -> tuple:
    """timed() for processes that run at the same time (wall seconds until the last ends)."""
    before = load()
    start = time.perf_counter()
    running = [subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
               for command in commands]
    for process, command in zip(running, commands):
        _, error = process.communicate()
        if process.returncode != 0:
            sys.exit(f"failed: {' '.join(map(str, command[:6]))} ...\n{error[-2000:]}")
    return time.perf_counter() - start, before, load()


def work_seconds(report: dict) -> float:
    return sum(entry["seconds"] for entry in report["results"])


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=200)
    parser.add_argument("--ratio", default="0.3")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--report", help="keep the cluster run's JSON report here")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    blender = shutil.which("blender")
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    with tempfile.TemporaryDirectory(prefix="topstoc-bench-batch-") as tmp:
        tmp = pathlib.Path(tmp)
        paths = make_assets(tmp / "assets", args.count, levels=(0, 1))
        from topstoc.core.api.io import read_mesh
        triangles = sum(read_mesh(p).num_triangles for p in paths)
        print(f"bench_batch: {len(paths)} assets, {triangles:,} triangles in all "
              f"({triangles // len(paths):,} per asset), --ratio {args.ratio}")
        print(f"machine: {machine()}")
        rows = []
        if blender is None:
            print("no blender on PATH: the one-Blender row is left out")
        else:
            out = tmp / "blender"
            seconds, *loads = timed([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                             str(BUILD / "python" / "topstoc" / "batch.py"), "--", "--input", *map(str, paths),
                             "--output", str(out), "--ratio", args.ratio, "--json", str(tmp / "blender.json")], env)
            report = json.loads((tmp / "blender.json").read_text())
            rows.append(("serial, one Blender (blender -b batch.py)", seconds, 1, report, out, loads))
        for label, workers in (("serial, no Blender (topstoc batch --workers 0)", 0),
                               (f"local Dask cluster, {args.workers} workers", args.workers)):
            out = tmp / f"workers{workers}"
            seconds, *loads = timed([sys.executable, "-m", "topstoc", "batch", "--input", str(tmp / "assets"), "--output",
                             str(out), "--ratio", args.ratio, "--workers", str(workers), "--progress", "lines"], env)
            report = json.loads((out / "topstoc-report.json").read_text())
            rows.append((label, seconds, max(1, workers), report, out, loads))
        # The folder split into chunks run side by side, one process each with the engine on one
        # thread (what the OpenJD template gives a farm: no Dask, each chunk its own task).
        chunks = max(2, args.workers)
        out = tmp / "chunks"
        chunk_env = dict(env, OMP_NUM_THREADS="1")
        seconds, *loads = timed_side_by_side(
            [[sys.executable, "-m", "topstoc", "batch", "--input", str(tmp / "assets"), "--output", str(out),
              "--ratio", args.ratio, "--workers", "0", "--chunk", f"{i}/{chunks}", "--progress", "lines"]
             for i in range(1, chunks + 1)], chunk_env)
        merged = {"results": [entry for i in range(1, chunks + 1)
                              for entry in json.loads((out / f"topstoc-report-chunk{i}of{chunks}.json").read_text())["results"]]}
        rows.append((f"{chunks} chunk processes side by side (--chunk I/{chunks} --workers 0, one thread each)",
                     seconds, chunks, merged, out, loads))
        reference = outputs(rows[0][4])
        identical = all(outputs(row[4]) == reference for row in rows[1:])
        print("\n| mode | wall s | assets/min | work s (sum) | overhead ms/asset | load before / after |")
        print("|---|---|---|---|---|---|")
        figures = []
        for label, seconds, processes, report, _, loads in rows:
            n = len(report["results"])
            overhead = (seconds * processes - work_seconds(report)) / n
            figures.append({"mode": label, "assets": n, "processes": processes, "wall_seconds": seconds,
                            "assets_per_minute": 60 * n / seconds, "work_seconds": work_seconds(report),
                            "overhead_ms_per_asset": 1000 * overhead, "load_before": loads[0], "load_after": loads[1]})
            print(f"| {label} | {seconds:.1f} | {60 * n / seconds:.0f} | {work_seconds(report):.1f} | "
                  f"{1000 * overhead:.0f} | {loads[0]:.2f} / {loads[1]:.2f} |")
        base = rows[0][1]
        for label, seconds, *_ in rows[1:]:
            print(f"{label}: {base / seconds:.2f}x the speed of '{rows[0][0]}'")
        print(f"outputs byte-identical across the modes: {identical}")
        cluster = next(row[3] for row in rows if row[0].startswith("local Dask cluster"))
        if args.json:
            pathlib.Path(args.json).write_text(json.dumps(
                {"machine": machine(), "assets": len(paths), "triangles": triangles, "ratio": args.ratio,
                 "outputs_identical": identical, "modes": figures}, indent=2))
        if args.report:
            pathlib.Path(args.report).write_text(json.dumps(cluster, indent=2))
        print("\ncluster run's report (first result; --report keeps all):")
        print(json.dumps({key: value for key, value in cluster.items() if key != "results"} |
                         {"results": cluster["results"][:1], "results_total": len(cluster["results"])}, indent=2))
        return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
