#!/usr/bin/python3
"""Two builds of the engine compared in paired runs of bench_decimate.py, the builds alternating.

    /usr/bin/python3 tests/bench/bench_threads_paired.py OLD_BUILD [NEW_BUILD] [--pairs 5]
        [--mesh MESH] [--ratio 0.1] [--repeats 3] [--json FILE]

Each pair runs bench_decimate.py (--no-peer) once on each build, in turn (old first in even
pairs, new first in odd ones, so a drift in the machine's load falls on both alike), and takes
new / old for each figure: first decimation, re-decimation, slider step, draft, quality mode.
On a shared, noisy machine the median of those ratios says more than the medians of the times.
Made for the move from OpenMP to the engine's own threads (OLD_BUILD: a build of the commit
before it); --json FILE saves the table for scripts/benchmarks_md.py.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine  # noqa: E402

DEFAULT_MESH = ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply"
# (label, where in bench_decimate.py's JSON): the figures compared.
FIGURES = [("first decimation", ("first_ms",)), ("re-decimation", ("ratios", 0, "fast_ms")),
           ("slider step", ("ratios", 0, "slider_step_ms")), ("draft", ("ratios", 0, "draft_ms")),
           ("draft slider step", ("ratios", 0, "draft_step_ms")), ("quality mode", ("ratios", 0, "quality_ms")),
           ("prepare", ("prepare_ms",))]


def figure(result: dict, where: tuple) -> float:
    for key in where:
        result = result[key]
    return float(result)


def run(build: pathlib.Path, args) -> dict:
    """One bench_decimate.py run on the given build: its JSON."""
    with tempfile.TemporaryDirectory() as folder:
        out = pathlib.Path(folder) / "result.json"
        subprocess.run([sys.executable, str(ROOT / "tests" / "bench" / "bench_decimate.py"), str(args.mesh),
                        "--ratios", str(args.ratio), "--repeats", str(args.repeats), "--no-peer", "--json", str(out)],
                       env=dict(os.environ, TOPSTOC_BENCH_BUILD=str(build)), check=True, capture_output=True)
        return json.loads(out.read_text())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=pathlib.Path, help="the reference build folder (with python/topstoc)")
    parser.add_argument("new", type=pathlib.Path, nargs="?", default=ROOT / "build")
    parser.add_argument("--pairs", type=int, default=5)
    parser.add_argument("--mesh", type=pathlib.Path, default=DEFAULT_MESH)
    parser.add_argument("--ratio", type=float, default=0.1)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", metavar="FILE", help="write the pairs and the median ratios here")
    args = parser.parse_args()
    if not args.mesh.exists():
        print(f"skipped: {args.mesh} not found (the benchmark mesh lives in ../shared/meshes)")
        return 0
    for build in (args.old, args.new):
        if not (build / "python" / "topstoc").is_dir():
            print(f"error: {build} holds no staged build (python/topstoc)", file=sys.stderr)
            return 2
    print(f"machine: {machine()}\nmesh: {args.mesh.name}, ratio {args.ratio}, {args.repeats} repeats per run")
    pairs = []
    for i in range(args.pairs):
        order = ("old", "new") if i % 2 == 0 else ("new", "old")
        results = {side: run(args.old if side == "old" else args.new, args) for side in order}
        pair = {label: {side: figure(results[side], where) for side in ("old", "new")} for label, where in FIGURES}
        pairs.append(pair)
        print(f"pair {i + 1} ({order[0]} first): " + ", ".join(
            f"{label} {p['new'] / p['old']:.3f}" for label, p in pair.items()), flush=True)
    medians = {label: statistics.median(p[label]["new"] / p[label]["old"] for p in pairs) for label, _ in FIGURES}
    print("\n| figure | old (median ms) | new (median ms) | median of new / old |\n|---|---|---|---|")
    for label, _ in FIGURES:
        old = statistics.median(p[label]["old"] for p in pairs)
        new = statistics.median(p[label]["new"] for p in pairs)
        print(f"| {label} | {old:.0f} | {new:.0f} | {medians[label]:.3f} |")
    if args.json:
        out = {"benchmark": "tests/bench/bench_threads_paired.py", "machine": machine(),
               "date": time.strftime("%Y-%m-%d", time.gmtime()), "load_average": os.getloadavg()[0],
               "mesh": args.mesh.name, "ratio": args.ratio, "repeats": args.repeats,
               "old": "OpenMP (libgomp)", "new": "the engine's own threads (core/parallel.hpp)",
               "pairs": pairs, "median_ratio": medians}
        pathlib.Path(args.json).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
