"""Batch throughput: assets per minute serially in one Blender, serially without Blender, on a
local Dask cluster with 2 worker processes, and as 2 chunk processes side by side (--chunk, as a
farm runs the OpenJD template), same assets, same run; overhead per asset.

    PATH=/var/cache/topstoc/venv-pipeline/bin:$PATH \\
        /var/cache/topstoc/venv-pipeline/bin/python tests/bench/bench_batch.py [--count 200] [--ratio 0.3]

The assets (the test meshes and synthetic ones at subdivision levels 0 and 1, under random
similarity transforms, OBJ/PLY/OFF) are generated into a temporary folder. Each mode writes its
own output folder; outputs of the three runs must be byte-identical (checked). Overhead per
asset = (wall time x processes - summed per-asset work) / assets: process start-up, reading,
writing, measuring, scheduling (the cluster's start-up included). Per mode, the per-asset time
with the error report against without it (the report's own seconds taken out). On the horse
(../shared/meshes/big, --horse-ratio): the Blender batch's time per asset with the default error
report (the quick bound) and with --exact-error, next to Blender's Decimate modifier at the same ratio. The JSON report of the cluster
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
HORSE = ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply"
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


def error_seconds(report: dict) -> float:
    """Seconds of the per-LOD error reports (in work_seconds; Blender-format assets report none)."""
    return sum(lod.get("hausdorff_seconds", 0.0) for entry in report["results"] for lod in entry.get("lods", []))


#: Blender's Decimate modifier (Collapse) applied to a mesh file read with topstoc's reader
MODIFIER_SCRIPT = """
import sys, time, bpy
from topstoc.core.api.io import read_mesh
path, ratio = sys.argv[sys.argv.index("--") + 1], float(sys.argv[-1])
data = read_mesh(path)
mesh = bpy.data.meshes.new("m")
mesh.from_pydata(data.vertices.tolist(), [], data.triangles.tolist())
obj = bpy.data.objects.new("m", mesh)
bpy.context.scene.collection.objects.link(obj)
bpy.context.view_layer.objects.active = obj
obj.select_set(True)
modifier = obj.modifiers.new("Decimate", "DECIMATE")
modifier.ratio = ratio
start = time.perf_counter()
bpy.ops.object.modifier_apply(modifier="Decimate")
print("MODIFIER_SECONDS", time.perf_counter() - start)
"""


def horse_rows(blender, env, tmp, ratio: str) -> dict:
    """The Blender batch on the horse (one asset, default error report and --exact-error) and the
    Decimate modifier on it, in this run."""
    if not HORSE.exists() or blender is None:
        print(f"horse rows left out: {HORSE} or blender missing")
        return {}
    figures = {}
    for label, flags in (("estimate", []), ("exact", ["--exact-error"])):
        report_path = tmp / f"horse-{label}.json"
        seconds, *_ = timed([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                             str(BUILD / "python" / "topstoc" / "batch.py"), "--", "--input", str(HORSE),
                             "--output", str(tmp / f"horse-{label}"), "--ratio", ratio, "--json",
                             str(report_path), *flags], env)
        report = json.loads(report_path.read_text())
        figures[label] = {"wall_seconds": seconds, "asset_seconds": work_seconds(report),
                          "error_seconds": error_seconds(report),
                          "lod": {k: v for k, v in report["results"][0]["lods"][0].items() if k.startswith("hausdorff")}}
    script = tmp / "modifier.py"
    script.write_text(MODIFIER_SCRIPT)
    done = subprocess.run([blender, "-b", "--factory-startup", "--python", str(script), "--", str(HORSE), ratio],
                          capture_output=True, text=True, env=env)
    line = next((l for l in done.stdout.splitlines() if l.startswith("MODIFIER_SECONDS")), None)
    figures["modifier_seconds"] = float(line.split()[1]) if line else None
    return figures


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=200)
    parser.add_argument("--ratio", default="0.3")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--report", help="keep the cluster run's JSON report here")
    parser.add_argument("--json", help="write the figures here")
    parser.add_argument("--horse-ratio", default="0.01",
                        help="the horse rows' ratio (the Blender batch and the Decimate modifier)")
    parser.add_argument("--no-horse", action="store_true", help="leave the horse rows out")
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
        errors = [(label, error_seconds(report), work_seconds(report)) for label, _, _, report, *_ in rows]
        for label, error, work in errors:
            print(f"{label}: per-asset time with the error report / without: {work / max(1e-9, work - error):.3f}x "
                  f"(error report {error:.1f} of {work:.1f} s)")
        horse = {} if args.no_horse else horse_rows(blender, env, tmp, args.horse_ratio)
        for label in ("estimate", "exact"):
            if label in horse:
                h = horse[label]
                print(f"horse, Blender batch ({label} error): {h['asset_seconds']:.2f} s per asset "
                      f"({h['error_seconds']:.2f} s of it the error report), {h['wall_seconds']:.1f} s wall; "
                      f"{h['lod']}")
        if horse.get("modifier_seconds"):
            m = horse["modifier_seconds"]
            print(f"horse, Blender's Decimate modifier at {args.horse_ratio}: {m:.2f} s; the Blender batch's asset "
                  f"time is {m / horse['estimate']['asset_seconds']:.1f}x faster (with --exact-error "
                  f"{m / horse['exact']['asset_seconds']:.1f}x)")
        cluster = next(row[3] for row in rows if row[0].startswith("local Dask cluster"))
        if args.json:
            pathlib.Path(args.json).write_text(json.dumps(
                {"benchmark": "tests/bench/bench_batch.py", "date": time.strftime("%Y-%m-%d"), "build": str(BUILD),
                 "method": f"--count {args.count} --ratio {args.ratio}, horse at {args.horse_ratio}; wall seconds on a "
                           "shared machine (load averages per mode); the error report's share from its own timing",
                 "machine": machine(), "assets": len(paths), "triangles": triangles, "ratio": args.ratio,
                 "outputs_identical": identical, "modes": figures,
                 "error_report": [{"mode": l, "error_seconds": e, "work_seconds": w} for l, e, w in errors],
                 "horse": horse}, indent=2))
        if args.report:
            pathlib.Path(args.report).write_text(json.dumps(cluster, indent=2))
        print("\ncluster run's report (first result; --report keeps all):")
        print(json.dumps({key: value for key, value in cluster.items() if key != "results"} |
                         {"results": cluster["results"][:1], "results_total": len(cluster["results"])}, indent=2))
        return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
