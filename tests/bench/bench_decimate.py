#!/usr/bin/python3
"""Decimation speed next to meshoptimizer, measured in the same run (issue 2 benchmark).

    /usr/bin/python3 tests/bench/bench_decimate.py [MESH] [--ratios 0.1,0.01] [--repeats 7] [--json FILE] [--no-peer]

The engine comes from build/python, or from TOPSTOC_BENCH_BUILD/python when that is set (another
build of the same checkout: bench_threads_paired.py compares two this way).

Default mesh: ../shared/meshes/big/horse_loop2_1.55M.ply (skips cleanly when absent). Times:
  - first decimation: topstoc.Mesh (validation, adjacency, weights) + decimate, file read excluded;
  - re-decimation: decimate on the prepared mesh, seeds 0..R-1 (each floods afresh);
  - slider step: the same seed at ratios 1 % apart, up and back down (what a slider drag costs:
    each updates the kept flood of the one before, native flood_cache.hpp);
  - first and re-decimation in the fast mode (plain TopStoc);
  - the same as drafts (draft=True: what the live slider shows while it moves; no attribute
    sources and no final output check), re-decimation with seeds R..2R-1 (unused, so each floods
    afresh) and slider steps;
  - the quality mode (the default: first pass, collapses, filtered re-fit) on the prepared mesh, 3 seeds,
    and cold (prepare + quality decimation at the first ratio);
  - meshopt_simplify (QEM edge collapse) and meshopt_simplifySloppy (grid clustering), via
    build/peers/meshopt_bench on the same file and the same vertex fraction of the index count.
Prints medians, the ratios and the machine; --json FILE also writes them (scripts/benchmarks_md.py
turns docs/bench_results/*.json into docs/benchmarks.md). Speed is never asserted in tests; it lives here.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BENCH_BUILD", ROOT / "build"))
sys.path.insert(0, str(BUILD / "python"))

from topstoc.core import Mesh, read_mesh  # noqa: E402
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine  # noqa: E402

DEFAULT_MESH = ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply"
PEER = BUILD / "peers" / "meshopt_bench"
REFINED = {"mode": "quality"}


def median_ms(values):
    return 1000 * statistics.median(values)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mesh", nargs="?", default=str(DEFAULT_MESH))
    parser.add_argument("--ratios", default="0.1,0.01")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--json", metavar="FILE", help="write the medians and the machine here")
    parser.add_argument("--no-peer", action="store_true", help="skip meshoptimizer (comparing our builds only)")
    args = parser.parse_args()
    path = pathlib.Path(args.mesh)
    if not path.exists():
        print(f"skipped: {path} not found (the benchmark mesh lives in ../shared/meshes)")
        return 0
    ratios = [float(r) for r in args.ratios.split(",")]
    data = read_mesh(path)
    print(f"mesh: {path.name}, {len(data.vertices)} vertices, {len(data.triangles)} triangles")
    print(f"machine: {machine()}")
    if os.getloadavg()[0] > 1.0:
        print("note: the machine is busy; medians are inflated (ratios less so, both sides are measured alike)")

    first = []
    for _ in range(3):
        start = time.perf_counter()
        mesh = Mesh(data.vertices, data.triangles)
        result = mesh.decimate(ratio=ratios[0], seed=0, mode="fast")
        first.append(time.perf_counter() - start)
    start = time.perf_counter()
    cold_quality = Mesh(data.vertices, data.triangles).decimate(ratio=ratios[0], seed=0)
    cold_quality_seconds = time.perf_counter() - start
    prepare = []
    for _ in range(3):
        start = time.perf_counter()
        mesh = Mesh(data.vertices, data.triangles)
        prepare.append(time.perf_counter() - start)

    rows = []
    for ratio in ratios:
        seconds, stages = [], {}
        for seed in range(args.repeats):
            start = time.perf_counter()
            result = mesh.decimate(ratio=ratio, seed=seed, mode="fast")
            seconds.append(time.perf_counter() - start)
            for name, value in result.stats.seconds.items():
                stages.setdefault(name, []).append(value)
        steps = []  # a drag: the same seed, ratios 1 % apart, each updating the flood before it
        path_ratios = [ratio * (1 + 0.01 * i) for i in list(range(-args.repeats, args.repeats + 1))]
        mesh.decimate(ratio=path_ratios[0] * 0.99, seed=1, mode="fast")
        updated = 0
        for step in path_ratios + path_ratios[::-1]:
            start = time.perf_counter()
            step_result = mesh.decimate(ratio=step, seed=1, mode="fast")
            steps.append(time.perf_counter() - start)
            updated += step_result.stats.flood_updated
        steps = (steps, updated)
        drafts = []  # live-preview frames: other seeds, each flooding afresh
        for seed in range(args.repeats, 2 * args.repeats):
            start = time.perf_counter()
            mesh.decimate(ratio=ratio, seed=seed, mode="fast", draft=True)
            drafts.append(time.perf_counter() - start)
        draft_steps = []
        mesh.decimate(ratio=path_ratios[0] * 0.99, seed=2, mode="fast", draft=True)
        for step in path_ratios + path_ratios[::-1]:
            start = time.perf_counter()
            mesh.decimate(ratio=step, seed=2, mode="fast", draft=True)
            draft_steps.append(time.perf_counter() - start)
        peer = None
        if PEER.exists() and not args.no_peer:
            out = subprocess.run([str(PEER), str(path), str(ratio), str(args.repeats)], capture_output=True,
                                 text=True, check=True)
            peer = json.loads(out.stdout)
        refined = []
        for seed in range(min(3, args.repeats)):  # quality mode: seconds, not milliseconds
            start = time.perf_counter()
            refined_result = mesh.decimate(ratio=ratio, seed=seed, **REFINED)
            refined.append(time.perf_counter() - start)
        rows.append((ratio, seconds, stages, result, peer, refined, refined_result, steps, (drafts, draft_steps)))

    print(f"\nprepare (validation, Morton order, adjacency, normals, weights): median {median_ms(prepare):.0f} ms")
    print(f"first decimation at {ratios[0]:.0%} (prepare + decimate): median {median_ms(first):.0f} ms")
    print("\n| target | ours: re-decimation | stages (sampling / clustering / checking / output / final check) | "
          "slider step | meshopt_simplify | meshopt_simplifySloppy | simplify / ours | sloppy / ours | "
          "simplify / slider step |")
    print("|---|---|---|---|---|---|---|---|---|")
    for ratio, seconds, stages, result, peer, _, _, (steps, updated), _ in rows:
        ours, step = median_ms(seconds), median_ms(steps)
        stage_text = " / ".join(f"{median_ms(stages[k]):.0f}" for k in ("sampling", "clustering", "checking", "output", "verify"))
        step_text = f"{step:.0f} ms ({updated} of {len(steps)} updated)"
        if peer:
            simplify = 1000 * peer["simplify"]["median_seconds"]
            sloppy = 1000 * peer["simplify_sloppy"]["median_seconds"]
            print(f"| {ratio:.0%} ({result.num_vertices} v, {result.num_triangles} t) | {ours:.0f} ms | {stage_text} ms | "
                  f"{step_text} | {simplify:.0f} ms ({peer['simplify']['vertices']} v) | "
                  f"{sloppy:.0f} ms ({peer['simplify_sloppy']['vertices']} v) | "
                  f"{simplify / ours:.1f}x | {sloppy / ours:.2f}x | {simplify / step:.1f}x |")
        else:
            print(f"| {ratio:.0%} | {ours:.0f} ms | {stage_text} ms | {step_text} | (build/peers/meshopt_bench missing) "
                  "| | | | |")
    print("\n| target | draft re-decimation, another seed | draft slider step | meshopt_simplify / draft |")
    print("|---|---|---|---|")
    for ratio, _, _, _, peer, _, _, _, (drafts, draft_steps) in rows:
        ours = median_ms(drafts)
        ratio_text = f"{1000 * peer['simplify']['median_seconds'] / ours:.1f}x" if peer else ""
        print(f"| {ratio:.0%} | {ours:.0f} ms | {median_ms(draft_steps):.0f} ms | {ratio_text} |")
    if rows[0][4]:
        simplify = rows[0][4]["simplify"]["median_seconds"]
        print(f"\nfirst decimation vs meshopt_simplify at {ratios[0]:.0%}: {simplify / statistics.median(first):.1f}x faster")
    print(f"\nquality mode (the default; a TopStoc first pass, then quadric edge collapses; see "
          f"bench_quality.py for its error): cold at {ratios[0]:.0%} {cold_quality_seconds:.2f} s "
          f"({cold_quality.num_vertices} v); re-decimation:")
    for ratio, _, _, _, peer, refined, refined_result, _, _ in rows:
        ours = statistics.median(refined)
        text = f"  {ratio:.0%} ({refined_result.num_vertices} v): median {1000 * ours:.0f} ms " \
               f"(refinement {1000 * refined_result.stats.seconds['refine']:.0f} ms)"
        if peer:
            text += f", meshopt_simplify / ours {peer['simplify']['median_seconds'] / ours:.2f}x"
        print(text)
    if args.json:
        figures = summary(path, data, args.repeats, prepare, first, cold_quality_seconds, rows)
        pathlib.Path(args.json).write_text(json.dumps(figures, indent=1) + "\n")
    return 0


def summary(path, data, repeats, prepare, first, cold_quality_seconds, rows) -> dict:
    """The printed medians as one JSON-ready dict (milliseconds; peer None when not built)."""
    out = {"benchmark": "tests/bench/bench_decimate.py", "machine": machine(),
           "date": time.strftime("%Y-%m-%d", time.gmtime()), "repeats": repeats,
           "mesh": {"name": path.name, "vertices": len(data.vertices), "triangles": len(data.triangles)},
           "prepare_ms": median_ms(prepare), "first_ms": median_ms(first),
           "cold_quality_ms": 1000 * cold_quality_seconds, "ratios": []}
    for ratio, seconds, stages, result, peer, refined, refined_result, (steps, updated), (drafts, draft_steps) in rows:
        out["ratios"].append({
            "ratio": ratio, "vertices": result.num_vertices, "triangles": result.num_triangles,
            "fast_ms": median_ms(seconds), "stages_ms": {k: median_ms(v) for k, v in stages.items()},
            "slider_step_ms": median_ms(steps), "slider_steps": len(steps), "slider_steps_updated": updated,
            "draft_ms": median_ms(drafts), "draft_step_ms": median_ms(draft_steps),
            "quality_ms": 1000 * statistics.median(refined), "quality_vertices": refined_result.num_vertices,
            "meshopt_simplify_ms": 1000 * peer["simplify"]["median_seconds"] if peer else None,
            "meshopt_sloppy_ms": 1000 * peer["simplify_sloppy"]["median_seconds"] if peer else None})
    return out


if __name__ == "__main__":
    sys.exit(main())
