"""Topology invariants and generator edges on a million-triangle mesh of genus 11, next to GUDHI.

    /usr/bin/python3 tests/bench/bench_topology.py [RUNS]

The mesh is ../shared/meshes/genus_positive/cgal_turbine.off after three rounds of Loop
subdivision by ../shared/tools/loop_subdiv.py (1,181,440 triangles, genus 11), made once into
build/bench/ (never committed). Also times the 1.55M-triangle horse of ../shared/meshes/big.
Ours: topstoc.core.api.topology.topology (invariants per component) and the same with
generators=True, as Python users call them (arrays in, dataclasses out). GUDHI 3.7: a
SimplexTree of the mesh (insert_batch), Z2 persistence and betti_numbers(), in the same run.
Goals (PEERS.md, issue 4): invariants <= 0.1 s, generators <= 0.3 s. Wall-clock medians are
printed with the load average, since the machine is shared; CPU seconds (all threads) too.
Skips cleanly without ../shared or a build.
"""

import os
import pathlib
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))
SHARED = ROOT.parent / "shared"
TURBINE = SHARED / "meshes" / "genus_positive" / "cgal_turbine.off"
HORSE = SHARED / "meshes" / "big" / "horse_loop2_1.55M.ply"
SUBDIVIDED = BUILD / "bench" / "turbine_loop3.ply"

sys.path.insert(0, str(BUILD / "python"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine  # noqa: E402


def load() -> str:
    return "load average " + " ".join(f"{x:.1f}" for x in os.getloadavg())


def timed(function, runs: int):
    """(median wall seconds, median CPU seconds of all threads, last result)."""
    walls, cpus, result = [], [], None
    for _ in range(runs):
        cpu, wall = time.process_time(), time.perf_counter()
        result = function()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return statistics.median(walls), statistics.median(cpus), result


def read(path: pathlib.Path):
    try:
        from topstoc.core.api.io import read_mesh
    except ImportError:  # before topstoc.core.api.io: the shared tools' reader
        sys.path.insert(0, str(SHARED / "tools"))
        import meshstat
        import numpy as np

        raw = meshstat.load(str(path))
        return raw.V, raw.fv.reshape(-1, 3).astype(np.int32)
    data = read_mesh(str(path))
    return data.vertices, data.triangles


def gudhi_betti(num_vertices, triangles):
    import gudhi
    import numpy as np

    tree = gudhi.SimplexTree()
    tree.insert_batch(np.arange(num_vertices).reshape(1, -1), np.zeros(num_vertices))
    tree.insert_batch(np.sort(triangles, axis=1).T.copy(), np.zeros(len(triangles)))
    tree.compute_persistence(homology_coeff_field=2, persistence_dim_max=True)
    return tuple((list(tree.betti_numbers()) + [0, 0, 0])[:3])


def bench(name, vertices, triangles, runs, gudhi_runs, generators=True):
    from topstoc.core.api.topology import topology

    print(f"\n{name}: {len(vertices)} vertices, {len(triangles)} triangles")
    wall, cpu, info = timed(lambda: topology(vertices, triangles), runs)
    print(f"  topstoc invariants            {wall:8.3f} s   (CPU {cpu:.3f} s)   {info.summary()}")
    ours = wall
    if generators:
        wall_g, cpu_g, info_g = timed(lambda: topology(vertices, triangles, generators=True), runs)
        counts = [len(g.edges) for g in info_g.generators]
        print(f"  topstoc invariants+generators {wall_g:8.3f} s   (CPU {cpu_g:.3f} s)   generator edges per "
              f"component {counts}, loop lengths median "
              f"{statistics.median([len(l) for g in info_g.generators for l in g.loops] or [0])}")
    try:
        import gudhi  # noqa: F401
    except ImportError:
        print("  GUDHI: not installed (apt-get install python3-gudhi)")
        return
    wall_gudhi, cpu_gudhi, betti = timed(lambda: gudhi_betti(len(vertices), triangles), gudhi_runs)
    print(f"  GUDHI SimplexTree Z2 Betti    {wall_gudhi:8.3f} s   (CPU {cpu_gudhi:.3f} s)   betti {betti}")
    print(f"  Betti numbers equal: {betti == info.betti}   ratio GUDHI / topstoc invariants: "
          f"{wall_gudhi / ours:.1f}x")
    if generators:
        print(f"  goals: invariants <= 0.1 s: {'met' if ours <= 0.1 else 'NOT met'} ({ours:.3f} s); "
              f"generators <= 0.3 s: {'met' if wall_g <= 0.3 else 'NOT met'} ({wall_g:.3f} s)")


def main() -> int:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    if not TURBINE.exists():
        print(f"skipped: {TURBINE} is not available")
        return 0
    try:
        import topstoc.core.api.topology  # noqa: F401
    except ImportError as error:
        print(f"skipped: no build ({error})")
        return 0
    if not SUBDIVIDED.exists():
        SUBDIVIDED.parent.mkdir(parents=True, exist_ok=True)
        print(f"making {SUBDIVIDED} (Loop subdivision x3 of {TURBINE.name}) ...")
        subprocess.run([sys.executable, str(SHARED / "tools" / "loop_subdiv.py"), str(TURBINE), str(SUBDIVIDED), "3"],
                       check=True, stdout=subprocess.DEVNULL)
    print(f"machine: {machine()}")
    bench("turbine, Loop subdivision x3 (genus 11)", *read(SUBDIVIDED), runs, gudhi_runs=min(runs, 3))
    if HORSE.exists():
        bench("horse, Loop subdivision x2 (genus 0)", *read(HORSE), runs, gudhi_runs=1, generators=False)
    print(f"\nafter: {load()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
