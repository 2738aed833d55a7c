#!/usr/bin/python3
"""Handle and tunnel loops on large genus >= 10 meshes, time per stage (issue 5 benchmark).

    /usr/bin/python3 tests/bench/bench_loops.py [--repeats 3] [--peer] [--verify] [--only NAME]
    /usr/bin/python3 tests/bench/bench_loops.py --families [--big] [--baseline DIR] [--json FILE]

--families (issue 39): the generated families of tests/loop_families.py (plates with irregular
holes, Swiss-cheese balls, lattices, Schwarz-P and gyroid surfaces, knotted and linked tubes),
time per family against its size and genus next to the 7 x 19 hole grid, wall and CPU seconds
(medians of --repeats; the wall clock also measures the neighbours on a shared machine); --big
adds the 1M-triangle member of genus 1,000 (one run). --baseline DIR times the same meshes with
another build's package (say, main's build/python) in a child process of the same run: the
before and after of a change. --json FILE saves the figures for scripts/benchmarks_md.py.

Meshes (made here with ../shared/tools/loop_subdiv.py into build/bench_meshes, never committed;
skips cleanly when ../shared is absent):
  turbine_l1  CGAL's turbine (genus 11), Loop-subdivided once:   73,840 triangles
  slab12_l3   a voxel slab with 12 holes (genus 12), 3 times:   117,760 triangles
  turbine_l3  the turbine, three times:                       1,181,440 triangles
  slab12_l5   the slab, five times:                           1,884,160 triangles
  grid133     a slab with 7 x 19 holes (genus 133):              14,912 triangles
  grid133_l3  the same, Loop-subdivided three times:            954,368 triangles
Times (medians of --repeats runs, file reading excluded): `mesh` = topstoc.Mesh (validation,
adjacency), `loops` = handle_tunnel_loops on it, `total` = both, and the loops' own stages.
CPU seconds are printed too: on a shared machine the wall clock also measures the neighbours.
The peer is the thesis' method done well: TetGen on the full mesh + the same persistence
(coarse_vertices=0), measured in the same run (--peer; on the ~1M meshes only with --peer-big:
minutes). --verify checks the returned loops independently on the full mesh: full
tetrahedralization, then GUDHI Betti numbers with the loops coned off (handles bound inside and
span the outside, tunnels the reverse, all span the surface).
"""

import argparse
import json
import os
import resource
import pathlib
import statistics
import subprocess
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = os.environ.get("TOPSTOC_BENCH_BUILD", str(ROOT / "build" / "python"))  # --baseline's child sets it
sys.path.insert(0, BUILD)
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "bench"))

from machine import machine, save_figures  # noqa: E402
from topstoc.core import Mesh, handle_tunnel_loops, read_mesh, tetrahedralize_surface, write_mesh  # noqa: E402
from topstoc.core.api.io import MeshData  # noqa: E402

SHARED = ROOT.parent / "shared"
OUT = ROOT / "build" / "bench_meshes"
CASES = [("turbine_l1", "turbine", 1), ("slab12_l3", "slab12", 3), ("turbine_l3", "turbine", 3),
         ("slab12_l5", "slab12", 5), ("grid133", "grid133", 0), ("grid133_l3", "grid133", 3)]


def base_mesh(name: str) -> pathlib.Path:
    if name == "turbine":
        return SHARED / "meshes" / "genus_positive" / "cgal_turbine.off"
    path = OUT / f"{name}.off"
    if not path.exists():
        import meshgen

        OUT.mkdir(parents=True, exist_ok=True)
        if name == "slab12":
            vertices, triangles = meshgen.genus_slab(12)
        else:  # grid133: genus 133 in few triangles, where the genus dominates the cost
            vertices, triangles = meshgen.genus_grid(7, 19, scale=(2, 2, 3))
        write_mesh(path, MeshData(vertices=vertices, triangles=triangles))
    return path


def make(name: str, base: str, levels: int) -> pathlib.Path:
    if levels == 0:
        return base_mesh(base)
    path = OUT / f"{name}.ply"
    if not path.exists():
        OUT.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, str(SHARED / "tools" / "loop_subdiv.py"), str(base_mesh(base)), str(path),
                        str(levels)], check=True, capture_output=True)
    return path


def cpu_seconds() -> float:
    """CPU time of this process and its finished children (TetGen runs in a forked child)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def timed(function):
    wall, cpu = time.perf_counter(), cpu_seconds()
    value = function()
    return value, time.perf_counter() - wall, cpu_seconds() - cpu


def verify(data, component) -> str:
    import homology_check as hc

    tets = tetrahedralize_surface(data.vertices, data.triangles)
    inside = tets["inside"].astype(bool)
    inner, outer, apex = [tets["tets"][inside]], [tets["tets"][~inside]], len(tets["points"])
    g = component.genus
    handles = [loop.vertices for loop in component.handles]
    tunnels = [loop.vertices for loop in component.tunnels]
    checks = {
        "b(inside)": hc.betti(inner)[:3] == [1, g, 0],
        "b(outside)": hc.betti(outer)[:3] == [1, g, 1],
        "handles bound inside": hc.coned_b1(inner, handles, apex) == g,
        "handles span outside": hc.coned_b1(outer, handles, apex) == 0,
        "tunnels bound outside": hc.coned_b1(outer, tunnels, apex) == g,
        "tunnels span inside": hc.coned_b1(inner, tunnels, apex) == 0,
        "all span the surface": hc.coned_b1([data.triangles], handles + tunnels, len(data.vertices)) == 0,
        "simple edge cycles": all(hc.is_simple_edge_cycle(loop.vertices, data.triangles) for loop in component.loops),
    }
    failed = [name for name, ok in checks.items() if not ok]
    return "all checks pass" if not failed else "FAILED: " + ", ".join(failed)


STAGES = ["prepare", "decimate", "self_intersections", "tetrahedralize", "persistence", "select", "map", "shorten",
          "verify"]


def time_family(name: str, repeats: int) -> dict:
    """One family member: its size, genus and the medians of `repeats` runs of the loops."""
    import loop_families

    vertices, triangles = {**loop_families.FAMILIES, **loop_families.BIG_FAMILIES}[name]()
    runs = [timed(lambda: handle_tunnel_loops(vertices, triangles)) for _ in range(repeats)]
    result = runs[-1][0]
    return {"name": name, "triangles": len(triangles), "components": len(result.components),
            "genus": sum(c.genus or 0 for c in result.components),
            "routes": sorted({c.route for c in result.components if c.route}),
            "seconds": statistics.median(r[1] for r in runs), "cpu": statistics.median(r[2] for r in runs),
            "stages": {k: statistics.median(r[0].seconds[k] for r in runs) for k in STAGES}}


def baseline(build: str, name: str, repeats: int) -> dict:
    """time_family with another build's package, in a child process."""
    out = subprocess.run([sys.executable, __file__, "--child", name, "--repeats", str(repeats)], check=True,
                         capture_output=True, text=True, env={**os.environ, "TOPSTOC_BENCH_BUILD": build})
    return json.loads(out.stdout.splitlines()[-1])


def families(args) -> int:
    import loop_families

    names = list(loop_families.FAMILIES) + (list(loop_families.BIG_FAMILIES) if args.big else [])
    print(f"machine: {machine()}")
    rows = []
    for name in names:
        repeats = 1 if name in loop_families.BIG_FAMILIES else args.repeats
        row = time_family(name, repeats)
        if args.baseline:
            before = baseline(args.baseline, name, repeats)
            row["baseline"] = {k: before[k] for k in ("seconds", "cpu", "stages")}
        rows.append(row)
        grid = rows[0]
        was = (f"; before {row['baseline']['seconds']:.2f} s (CPU {row['baseline']['cpu']:.2f} s, select "
               f"{row['baseline']['stages']['select']:.2f} s)") if args.baseline else ""
        print(f"{name}: {row['triangles']:,} triangles, genus {row['genus']} in {row['components']} component(s), "
              f"{'/'.join(row['routes'])} route: {row['seconds']:.2f} s (CPU {row['cpu']:.2f} s, select "
              f"{row['stages']['select']:.2f} s), {row['cpu'] / grid['cpu']:.2f}x the grid's CPU{was}", flush=True)
    if args.json:
        save_figures(args.json, "tests/bench/bench_loops.py --families",
                     "handle_tunnel_loops(vertices, triangles) per family member (tests/loop_families.py), wall and "
                     "CPU seconds, medians of the repeats (one run at 1M triangles); "
                     + ("the baseline is " + args.baseline + " timed in a child process of the same run"
                        if args.baseline else "no baseline"), repeats=args.repeats, families=rows)
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--families", action="store_true", help="time the generated families (issue 39)")
    parser.add_argument("--big", action="store_true", help="with --families: also the 1M-triangle member")
    parser.add_argument("--baseline", help="with --families: another build's python directory, timed alongside")
    parser.add_argument("--json", help="with --families: save the figures here")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--peer", action="store_true", help="also time the full route on the ~100k meshes")
    parser.add_argument("--peer-big", action="store_true", help="also time the full route on the ~1M meshes")
    parser.add_argument("--verify", action="store_true", help="check the loops on the full tetrahedralization")
    parser.add_argument("--only", help="run only this case")
    args = parser.parse_args()
    if args.child:
        print(json.dumps(time_family(args.child, args.repeats)))
        return 0
    if args.families:
        return families(args)
    if not (SHARED / "tools" / "loop_subdiv.py").exists():
        print(f"skipped: {SHARED / 'tools'} not found (the benchmark meshes are made from ../shared)")
        return 0
    print(f"machine: {machine()}")
    stage_names = ["prepare", "decimate", "self_intersections", "tetrahedralize", "persistence", "select", "map",
                   "shorten", "verify"]
    for name, base, levels in CASES:
        if args.only and name != args.only:
            continue
        data = read_mesh(make(name, base, levels))
        print(f"\n== {name}: {len(data.vertices)} vertices, {len(data.triangles)} triangles")
        runs = []
        for _ in range(args.repeats):
            mesh, mesh_wall, mesh_cpu = timed(lambda: Mesh(data.vertices, data.triangles))
            result, loops_wall, loops_cpu = timed(lambda: handle_tunnel_loops(mesh))
            runs.append((mesh_wall, loops_wall, mesh_cpu, loops_cpu, result))
        result = runs[-1][4]
        (component,) = result.components
        median = lambda i: statistics.median(r[i] for r in runs)  # noqa: E731
        print(f"genus {component.genus}: {len(component.handles)} handles, {len(component.tunnels)} tunnels; "
              f"{component.route} route, coarse target {result.coarse_target}, "
              f"{result.coarse_rounds} refinement rounds (+{result.coarse_samples_added} samples), "
              f"{component.analysed_vertices} vertices / {component.tetrahedra} tetrahedra tetrahedralized")
        print(f"total {median(0) + median(1):.3f} s (mesh {median(0):.3f} s + loops {median(1):.3f} s), "
              f"CPU {median(2) + median(3):.3f} s; medians of {args.repeats}, load average {os.getloadavg()[0]:.2f}")
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(f"peak resident memory of this process so far: {peak:.0f} MB (one case alone: --only {name})")
        stages = {k: statistics.median(r[4].seconds[k] for r in runs) for k in stage_names}
        print("stages (s): " + ", ".join(f"{k} {v:.3f}" for k, v in stages.items()))
        for kind, loops in (("handles", component.handles), ("tunnels", component.tunnels)):
            lengths = np.array([loop.length for loop in loops])
            initial = np.array([loop.initial_length for loop in loops])
            edges = np.array([len(loop) for loop in loops])
            print(f"{kind}: length mean {lengths.mean():.4f} (min {lengths.min():.4f}, max {lengths.max():.4f}), "
                  f"before shortening {initial.mean():.4f}; edges mean {edges.mean():.0f}")
        big = len(data.triangles) > 500000
        if (args.peer and not big) or (args.peer_big and big):
            peer, peer_wall, peer_cpu = timed(lambda: handle_tunnel_loops(Mesh(data.vertices, data.triangles),
                                                                          coarse_vertices=0))
            ours = median(0) + median(1)
            (full,) = peer.components
            print(f"peer (full route: TetGen on the whole mesh + persistence): {peer_wall:.3f} s wall, "
                  f"CPU {peer_cpu:.3f} s, {full.tetrahedra} tetrahedra; ratio {peer_wall / ours:.1f}x; "
                  f"its loops: handles mean {np.mean([x.length for x in full.handles]):.4f}, "
                  f"tunnels mean {np.mean([x.length for x in full.tunnels]):.4f}")
            print("peer stages (s): " + ", ".join(f"{k} {peer.seconds[k]:.3f}" for k in stage_names))
        if args.verify:
            report, wall, _ = timed(lambda: verify(data, component))
            print(f"independent check on the full mesh ({wall:.0f} s): {report}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
