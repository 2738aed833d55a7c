"""Error-bounded search benchmark: targets decimated, probes and time of ``max_error`` searches
next to one count-target decimation at the answer's count (a fresh mesh each, so both pay the
preparation), in both modes, on fourteen cases of eleven meshes. Each case runs in a child process;
with ``--baseline DIR`` (another build's python directory, e.g. main's) the baseline's search runs
right after ours in the same run.
Set TOPSTOC_NUM_THREADS=1 for CPU figures of one thread.

    /usr/bin/python3 tests/bench/bench_error_search.py [--mode quality|fast ...] [--baseline DIR] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tests" / "bench"), str(ROOT / "tests")]

from machine import machine  # noqa: E402

BUNNY = ROOT.parent / "shared" / "meshes" / "genus0" / "cgal_bunny00.off"
DATA = ROOT / "tests" / "data"
#: (mesh, relative bound): scans, CAD parts, figures, a knot and two open meshes
CASES = [(BUNNY, 0.003), (BUNNY, 0.01), (DATA / "genus_positive/cgal_elephant.off", 0.01),
         (DATA / "genus_positive/cgal_elephant.off", 0.003), (DATA / "genus0/cgal_fandisk.off", 0.003),
         (DATA / "genus0/cgal_fandisk.off", 0.01), (DATA / "genus_positive/cgal_eight.off", 0.01),
         (DATA / "genus0/cgal_armadillo.off.gz", 0.005), (DATA / "genus0/cgal_ChineseDragon-10kv.off", 0.005),
         (DATA / "open_boundary/cgal_mushroom.off", 0.02), (DATA / "genus_positive/cgal_turbine.off", 0.005),
         (DATA / "open_boundary/kivy_suzanne_monkey.obj", 0.01), (DATA / "genus_positive/cgal_knot1.off", 0.002),
         (DATA / "genus_positive/cgal_anchor_dense.off", 0.003)]


def timed(owner, name: str, split: dict, key: str) -> None:
    """Replaces owner.name by a wrapper adding its calls and CPU seconds to split[key]."""
    inner = getattr(owner, name)

    def wrapper(*args, **kwargs):
        cpu = time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            calls, seconds = split.get(key, (0, 0.0))
            split[key] = (calls + 1, seconds + time.process_time() - cpu)

    setattr(owner, name, wrapper)


def run(path: str, bound: float, mode: str) -> dict:
    """One search and one count-target decimation at its answer, each on a fresh mesh (in this
    process: the build on sys.path). split: calls and CPU seconds of the search's decimations
    (engine calls), exact checks and sampled estimates."""
    import importlib

    import topstoc

    api = topstoc.__name__ + ".core.api."
    error_bound = importlib.import_module(api + "error_bound")
    split = {}
    timed(importlib.import_module(api + "decimate").engine, "decimate", split, "decimations")
    timed(error_bound, "decide_error", split, "exact_checks")
    timed(error_bound.SampledError, "__call__", split, "estimates")
    mesh = importlib.import_module(api + "io").read_mesh(pathlib.Path(path))
    vertices, triangles = mesh.vertices, mesh.triangles
    started, cpu = time.perf_counter(), time.process_time()
    report = topstoc.Mesh(vertices, triangles).decimate(max_error=bound, relative=True, seed=1,
                                                        mode=mode).error_bound
    search, search_cpu = time.perf_counter() - started, time.process_time() - cpu
    split = {key: {"calls": calls, "cpu": seconds} for key, (calls, seconds) in split.items()}
    started, cpu = time.perf_counter(), time.process_time()
    topstoc.Mesh(vertices, triangles).decimate(target_vertices=report.target_vertices, seed=1, mode=mode)
    count, count_cpu = time.perf_counter() - started, time.process_time() - cpu
    return dict(probes=len(report.probes), decimated=len({target for target, *_ in report.probes}),
                target=report.target_vertices, failed=report.failed_target, achieved=report.achieved_error / report.max_error,
                search=search, search_cpu=search_cpu, count=count, count_cpu=count_cpu, split=split)


def split_line(split: dict) -> str:
    """Calls and CPU seconds of each part of a search."""
    return ", ".join(f"{key} {part['calls']} {part['cpu']:.2f} s" for key, part in sorted(split.items()))


def child(build: pathlib.Path, path: pathlib.Path, bound: float, mode: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(build))
    out = subprocess.run([sys.executable, __file__, "--child", str(path), str(bound), mode], env=env,
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mode", action="append", choices=["quality", "fast"])
    parser.add_argument("--baseline", type=pathlib.Path, help="another build's python directory, run in the same run")
    parser.add_argument("--json", type=pathlib.Path, help="save the figures here (docs/bench_results/)")
    parser.add_argument("--note", help="a line saved with the figures (what the run compares)")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(run(args.child[0], float(args.child[1]), args.child[2])))
        return
    print(f"machine: {machine()}")
    rows = []
    for path, bound in CASES:
        if not path.exists():
            print(f"{path.name}: missing, skipped")
            continue
        for mode in args.mode or ["quality", "fast"]:
            r = dict(mesh=path.name, bound=bound, mode=mode, **child(ROOT / "build" / "python", path, bound, mode))
            if args.baseline:
                r["baseline"] = child(args.baseline, path, bound, mode)
            rows.append(r)
            before = r.get("baseline")
            print(f"{r['mesh']:22s} {bound:6.1%} {mode:8s} decimated {r['decimated']:3d} probes {r['probes']:3d} "
                  f"target {r['target']:6d} failed {r['failed']:6d} search {r['search']:6.2f} s "
                  f"count {r['count']:5.2f} s ratio {r['search'] / r['count']:6.1f} CPU ratio "
                  f"{r['search_cpu'] / r['count_cpu']:6.1f} " + split_line(r['split'])
                  + ("" if before is None else
                     f" | baseline decimated {before['decimated']:3d} target {before['target']:6d} "
                     f"search {before['search']:6.2f} s ratio {before['search'] / before['count']:6.1f}"), flush=True)
    if args.json:
        report = {"benchmark": "tests/bench/bench_error_search.py", "machine": machine(),
                  "date": time.strftime("%Y-%m-%d"), "cases": rows, **({"note": args.note} if args.note else {}),
                  "method": "one max_error search (seed 1) and one count-target decimation at its answer, each on a "
                            "fresh mesh in a child process; wall and CPU seconds; the baseline build in the next child; "
                            f"TOPSTOC_NUM_THREADS={os.environ.get('TOPSTOC_NUM_THREADS', 'unset')}"}
        args.json.write_text(json.dumps(report, indent=1) + "\n")


if __name__ == "__main__":
    main()
