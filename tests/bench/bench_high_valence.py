#!/usr/bin/python3
"""Vertices of very high valence (issue 39, "no slow corner"): decimation time on fans of
slivers around one vertex, next to another build of the engine in the same run (this one is
TOPSTOC_BUILD's, else build/).

    /usr/bin/python3 tests/bench/bench_high_valence.py
    /usr/bin/python3 tests/bench/bench_high_valence.py --baseline /tmp/main-build/python \\
        --json docs/bench_results/bench_high_valence.json

The family: a double cone (two apexes joined to a rim of n vertices, 2n triangles, closed genus
0) at n = 10,000 to 80,000; and what an artist meets: a UV sphere of 2,000 segments
(poles of valence 2,000), a disc fanned from one centre of valence 50,000 (open boundary) and
CAD-like cylinders of 128 to 5,000 segments whose caps are fans (at 10 % those of 128 and 256
segments are fitted in four rounds, that of 1,000 in one: tiny_fit.cpp). Each mesh is decimated to --ratio
(10 %) of its vertices in each mode of --modes, seed 0, in a fresh process per build with
TOPSTOC_NUM_THREADS=1; the time is decimate() alone (the Mesh is prepared before the clock starts), the
best of --repeat runs. Each result's symmetric Hausdorff error (mean and max, % of the diagonal,
100,000 samples) is measured after the clock, so that a faster build is seen to give the same
quality. --baseline runs the same in a process importing topstoc from that folder (main's build:
the figures before a change), with a time limit (a quadratic build can take minutes). --cases
shape:size,... replaces the family (e.g. cylinder_caps:2000,cylinder_caps:8333 at --ratio 0.01).
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine, save_figures  # noqa: E402

CASES = [("cone", 10000), ("cone", 20000), ("cone", 40000), ("cone", 80000), ("uv_sphere", 2000),
         ("fan_disc", 50000), ("cylinder_caps", 128), ("cylinder_caps", 256), ("cylinder_caps", 1000),
         ("cylinder_caps", 5000)]

CHILD = r"""
import json, sys, time
import numpy as np
import topstoc as ts

from fan_meshes import cone, cylinder_caps, fan_disc, uv_sphere  # noqa: F401 (looked up by name)

shape, size, repeat, ratio = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[5])
P, T = globals()[shape](size)
mesh = ts.Mesh(P, T)
out = {"triangles": int(len(T)), "vertices": int(len(P))}
for mode in sys.argv[4].split(","):
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        result = ts.decimate(mesh, ratio=ratio, mode=mode, seed=0)
        seconds = time.perf_counter() - start
        best = seconds if best is None else min(best, seconds)
    error = ts.hausdorff(mesh, result, samples=100000, relative=True, max_tolerance=0).symmetric
    out[mode] = {"seconds": best, "output_triangles": int(result.num_triangles),
                 "error_mean": 100 * error.mean, "error_max": 100 * error.max}
print(json.dumps(out))
"""


def run(python_path: str, shape: str, size: int, repeat: int, modes: str, limit: float, ratio: float):
    """The child's figures for one mesh, or None when it ran past `limit` seconds."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([python_path, str(ROOT / "tests")]), TOPSTOC_NUM_THREADS="1")
    try:
        done = subprocess.run([sys.executable, "-c", CHILD, shape, str(size), str(repeat), modes, str(ratio)], env=env,
                              capture_output=True, text=True, timeout=limit, check=True)
    except subprocess.TimeoutExpired:
        return None
    return json.loads(done.stdout.splitlines()[-1])


def describe(row: dict, mode: str, args) -> str:
    """One mode's time, and the baseline's beside it when there is one."""
    ours, base = row["ours"], row.get("baseline")
    text = f"{mode} {ours[mode]['seconds']:.2f} s" if ours else f"{mode} over {args.limit:.0f} s"
    if ours:
        text += f" [error mean {ours[mode]['error_mean']:.3g} %, max {ours[mode]['error_max']:.3g} %]"
    if args.baseline and base and ours:
        text += (f" (baseline {base[mode]['seconds']:.2f} s, {base[mode]['seconds'] / ours[mode]['seconds']:.1f}x"
                 f" [{base[mode]['error_mean']:.3g} %, {base[mode]['error_max']:.3g} %])")
    elif args.baseline:
        text += " (baseline " + (f"{base[mode]['seconds']:.2f} s)" if base else f"over {args.limit:.0f} s)")
    return text


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--baseline", metavar="DIR", help="another build's python folder, run beside this one")
    parser.add_argument("--repeat", type=int, default=2, help="runs per mode (the best is kept)")
    parser.add_argument("--limit", type=float, default=600.0, help="seconds allowed per mesh and build")
    parser.add_argument("--modes", default="quality,fast", help="comma-separated modes to time")
    parser.add_argument("--json", metavar="FILE", help="write the figures and the machine here")
    parser.add_argument("--ratio", type=float, default=0.1, help="share of the vertices kept")
    parser.add_argument("--cases", default="", help="shape:size,... instead of the family")
    args = parser.parse_args()
    modes = args.modes.split(",")
    cases = [(c.split(":")[0], int(c.split(":")[1])) for c in args.cases.split(",")] if args.cases else CASES
    ours = str(pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python")
    print(f"machine: {machine()}")
    rows = []
    for shape, size in cases:
        row = {"shape": shape, "size": size,
               "ours": run(ours, shape, size, args.repeat, args.modes, args.limit, args.ratio)}
        if args.baseline:
            row["baseline"] = run(args.baseline, shape, size, args.repeat, args.modes, args.limit, args.ratio)
        rows.append(row)
        print(f"{shape:14} {size:>7,}: " + ", ".join(describe(row, mode, args) for mode in modes), flush=True)
        if args.json:  # after every mesh: a run stopped part-way keeps the meshes done
            save_figures(args.json, "tests/bench/bench_high_valence.py",
                         f"decimate() to {args.ratio:.0%} of the vertices, seed 0, one thread, best of --repeat runs "
                         "in a fresh process per mesh and build, then the result's Hausdorff error; baseline: the "
                         "same with main's build",
                         ratio=args.ratio, repeat=args.repeat, modes=modes, limit_s=args.limit, meshes=rows)
    cones = [r for r in rows if r["shape"] == "cone" and r["ours"]]
    for mode in modes if len(cones) > 1 else []:
        t0, t1 = cones[0]["ours"][mode]["seconds"], cones[-1]["ours"][mode]["seconds"]
        print(f"cone {mode}: {cones[-1]['size'] / cones[0]['size']:.0f}x the triangles took {t1 / t0:.1f}x the time")
    return 0


if __name__ == "__main__":
    sys.exit(main())
