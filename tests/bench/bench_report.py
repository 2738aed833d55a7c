#!/usr/bin/python3
"""The error report's cost next to the decimation it measures, on big originals of several kinds
(issue 39, item 3: the report at most 20 % of the decimation).

    /usr/bin/python3 tests/bench/bench_report.py [--baseline BUILD] [--cases a,b] [--repeats 2] [--json FILE]

Each case is an original of 237k to 1.55M triangles decimated in quality mode: CAD and organic
test meshes subdivided into coplanar triangles (`meshgen.subdivide`: the result can lie on its
original, the hardest case for a bound), the 1.55M-triangle horse (../shared/meshes/big, skipped
and named when absent) and a cylinder whose caps are fans of 50,000 slivers. Per case, on one
thread: the decimation's CPU seconds, and the default report's (`estimate_error` with the quick
bound, as the batch runs it) with its bracket, for this build and, with --baseline, for another
build's in the same run, case by case, alternating; best of --repeats.
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
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))
SHARED = ROOT.parent / "shared" / "meshes"
HORSE = SHARED / "big" / "horse_loop2_1.55M.ply"
DATA = ROOT / "tests" / "data"

# name: (source, subdivision levels, ratio)
CASES = {
    "fandisk x3 at 1.57 %": ("genus0/cgal_fandisk.off", 3, 0.0157),
    "fandisk x3 at 10 %": ("genus0/cgal_fandisk.off", 3, 0.1),
    "fandisk x3 at 30 %": ("genus0/cgal_fandisk.off", 3, 0.3),
    "anchor x3 at 3 %": ("genus_positive/cgal_anchor_dense.off", 3, 0.03),
    "anchor x3 at 10 %": ("genus_positive/cgal_anchor_dense.off", 3, 0.1),
    "couplingdown x3 at 10 %": ("genus_positive/cgal_couplingdown.off", 3, 0.1),
    "turbine x2 at 3 %": ("genus_positive/cgal_turbine.off", 2, 0.03),
    "elephant x3 at 2 %": ("genus_positive/cgal_elephant.off", 3, 0.02),
    "elephant x3 at 30 %": ("genus_positive/cgal_elephant.off", 3, 0.3),
    "knot x3 at 30 %": ("genus_positive/cgal_knot1.off", 3, 0.3),
    "horse at 1 %": ("horse", 0, 0.01),
    "horse at 10 %": ("horse", 0, 0.1),
    "fanned cylinder at 0.2 %": ("fans", 0, 0.002),
}


def original(source: str, levels: int):
    """The case's original (vertices, triangles), or None where its file is absent."""
    sys.path.insert(0, str(ROOT / "tests"))
    from fan_meshes import cylinder_caps
    from meshgen import subdivide
    from topstoc.core.api.io import read_mesh
    if source == "fans":
        return cylinder_caps(50000, 4)
    path = HORSE if source == "horse" else DATA / source
    if not path.exists():
        return None
    mesh = read_mesh(path)
    return subdivide(mesh.vertices, mesh.triangles, levels) if levels else (mesh.vertices, mesh.triangles)


def worker(name: str, repeats: int) -> dict:
    """One case on this process's build: the decimation and the default report, CPU seconds."""
    import importlib

    import topstoc
    estimates = importlib.import_module(topstoc.__name__ + ".core.api.error_estimate")
    source, levels, ratio = CASES[name]
    mesh = original(source, levels)
    if mesh is None:
        return {"case": name, "missing": True}
    decimation, report = [], []
    for _ in range(repeats):
        start = time.process_time()
        result = topstoc.Mesh(*mesh).decimate(ratio=ratio, seed=1)
        decimation.append(time.process_time() - start)
        start = time.process_time()
        bound = estimates.estimate_error(mesh, (result.vertices, result.triangles))
        report.append(time.process_time() - start)
    diagonal = float(((mesh[0].max(0) - mesh[0].min(0)) ** 2).sum() ** 0.5)
    return {"case": name, "triangles": int(len(mesh[1])), "result_triangles": int(len(result.triangles)),
            "decimation_seconds": min(decimation), "report_seconds": min(report),
            "estimate": bound.estimate / diagonal, "upper": bound.upper / diagonal, "converged": bound.converged}


def run(build: pathlib.Path, name: str, repeats: int) -> dict:
    """worker() in a fresh process on `build`, on one thread."""
    environment = dict(os.environ, OMP_NUM_THREADS="1", TOPSTOC_NUM_THREADS="1", PYTHONPATH=str(build / "python"))
    done = subprocess.run([sys.executable, __file__, "--worker", name, "--repeats", str(repeats)], env=environment,
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"error: {name} on {build}: {done.stderr.strip().splitlines()[-1:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--baseline", type=pathlib.Path, help="another build's folder, measured in the same run")
    parser.add_argument("--cases", help="comma-separated case names (default: all)")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--json", help="write the figures here (for scripts/benchmarks_md.py)")
    parser.add_argument("--label", default="", help="a few words on what this run compares")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker, args.repeats)))
        return 0
    names = args.cases.split(",") if args.cases else list(CASES)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise SystemExit(f"error: unknown case(s) {unknown}; known: {', '.join(CASES)}")
    rows = []
    print(f"{'case':26s} {'triangles':>19s} {'decimation':>10s} {'report':>7s} {'share':>6s} {'baseline':>8s}")
    for name in names:
        row = run(BUILD, name, args.repeats)
        if args.baseline and not row.get("missing"):
            row["baseline"] = run(args.baseline, name, args.repeats)
        rows.append(row)
        if row.get("missing"):
            print(f"{name:26s} skipped: its original is absent")
            continue
        base = f"{row['baseline']['report_seconds']:8.2f}" if "baseline" in row else ""
        print(f"{name:26s} {row['triangles']:>9,} -> {row['result_triangles']:>7,} {row['decimation_seconds']:10.2f} "
              f"{row['report_seconds']:7.2f} {row['report_seconds'] / row['decimation_seconds']:6.0%} {base}", flush=True)
    if args.json:
        sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
        from machine import save_figures
        save_figures(args.json, "tests/bench/bench_report.py",
                     "one thread, CPU seconds, best of %d; the report is estimate_error's default (the quick bound, "
                     "the exact walk for a side it leaves open)" % args.repeats,
                     label=args.label, baseline=str(args.baseline or ""), cases=rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
