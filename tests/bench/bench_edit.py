"""Benchmark: topology editing on ~1M triangles, and hole filling against CGAL.

    /usr/bin/python3 tests/bench/bench_edit.py [--repeats N]

Cases
  * torus 1M: a 1000 x 500 torus (1,000,000 triangles); remove the handle along a meridian
    (500-vertex loop): cut + fill both holes.
  * turbine x3: ../shared/meshes/genus_positive/cgal_turbine.off after three rounds of Loop
    subdivision (1,181,440 triangles, genus 11); remove a handle along a handle loop of the
    coarse mesh (topstoc.core.api.loops; a tree-cotree generator loop without it) carried through
    the subdivision (its vertices keep their ids, edge midpoints join them).
  * elephant-with-holes: fill all 106 holes, ours vs CGAL's triangulate_hole (peer program
    build/peers/cgal_edit, timed inside the program, reading excluded).
  * cut sides of the torus: fill the two 500-vertex holes, ours vs CGAL.

Prints medians of wall time and of process CPU time (the machine may be shared: CPU time is
the steadier figure), the ratio to the peer, the meshes and the machine. Skips what needs
../shared or a peer that is not there.
"""

from __future__ import annotations

import argparse
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"
sys.path[:0] = [str(ROOT / "build" / "python"), str(ROOT / "tests"), str(ROOT / "tests" / "python"),
                str(ROOT / "tests" / "bench")]

import meshgen  # noqa: E402
from machine import machine  # noqa: E402
from test_edit import generator_loop, read_off, write_off  # noqa: E402
from topstoc.core.api import edit  # noqa: E402

CGAL_EDIT = ROOT / "build" / "peers" / "cgal_edit"


def timed(function, repeats: int):
    walls, cpus, result = [], [], None
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        result = function()
        cpus.append(time.process_time() - c)
        walls.append(time.perf_counter() - w)
    return float(np.median(walls)), float(np.median(cpus)), result


def report(name: str, wall: float, cpu: float, extra: str = "") -> None:
    print(f"  {name:<34} median wall {wall * 1e3:8.1f} ms   cpu {cpu * 1e3:8.1f} ms  {extra}")


def loop_subdivide(vertices, triangles, loop, levels: int):
    """Loop subdivision by ../shared/tools/loop_subdiv.py, carrying a vertex loop along: old
    vertices keep their ids and the midpoint of edge (a, b) gets id n + rank of (a, b)."""
    sys.path.insert(0, str(SHARED / "tools"))
    import loop_subdiv  # noqa: E402  (shared tool, not part of the project)
    for _ in range(levels):
        n = len(vertices)
        t = np.asarray(triangles, dtype=np.int64)
        he = np.stack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]], 1).reshape(-1, 2)
        keys = np.unique(he.min(1) * n + he.max(1))
        fine = []
        for a, b in zip(loop, loop[1:] + loop[:1]):
            fine += [a, n + int(np.searchsorted(keys, min(a, b) * n + max(a, b)))]
        vertices, triangles = loop_subdiv.loop_once(vertices, t)
        loop = fine
    return vertices, np.asarray(triangles, dtype=np.int32), loop


def cgal_fill(vertices, triangles, repeats: int):
    """(median wall, median CPU) seconds of CGAL filling every hole, or None without the peer."""
    if not CGAL_EDIT.exists():
        return None
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "holes.off"
        write_off(path, vertices, triangles)
        out = subprocess.run([str(CGAL_EDIT), "fill-holes", str(path), str(repeats)], capture_output=True, text=True,
                             check=True).stdout.split()
    return float(out[out.index("seconds") + 1]), float(out[out.index("cpu") + 1])


def bench_remove_handle(title, vertices, triangles, loop, repeats):
    print(f"{title}: {len(vertices)} vertices, {len(triangles)} triangles, loop of {len(loop)} vertices")
    wall, cpu, cut = timed(lambda: edit.cut_along_loop(vertices, triangles, loop), repeats)
    report("cut_along_loop", wall, cpu)
    sides = [side.vertices for side in cut.cut_sides]
    wall, cpu, _ = timed(lambda: edit.fill_loops(cut.vertices, cut.triangles, sides), repeats)
    report("fill_loops (both sides)", wall, cpu)
    wall, cpu, result = timed(lambda: edit.remove_handle(vertices, triangles, loop), repeats)
    report("remove_handle (cut + fill)", wall, cpu,
           f"methods {[p.method for p in result.patches]}, +{result.num_triangles - len(triangles)} triangles")
    wall, cpu, _ = timed(lambda: edit.boundary_loops(cut.vertices, cut.triangles), repeats)
    report("boundary_loops (after the cut)", wall, cpu)
    wall, cpu, _ = timed(lambda: edit.fill_holes(cut.vertices, cut.triangles), repeats)
    report("fill_holes (finds and fills both)", wall, cpu)
    peer = cgal_fill(cut.vertices, cut.triangles, repeats)
    if peer is not None:
        ours_wall, ours_cpu, _ = timed(lambda: edit.fill_loops(cut.vertices, cut.triangles, sides), repeats)
        report("CGAL triangulate_hole, same holes", *peer,
               f"ours/CGAL wall {ours_wall / peer[0]:.2f}, cpu {ours_cpu / peer[1]:.2f} (CGAL fills in place; "
               "ours returns new arrays and maps)")
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    print(f"machine: {machine()}")

    vertices, triangles = meshgen.torus(1000, 500)
    bench_remove_handle("torus 1M", vertices, triangles, list(range(500)), args.repeats)

    turbine = SHARED / "meshes" / "genus_positive" / "cgal_turbine.off"
    if (SHARED / "tools" / "loop_subdiv.py").exists() and turbine.exists():
        coarse_v, coarse_t = read_off(turbine)
        try:  # a real handle loop when the loops module is built, else a tree-cotree generator
            from topstoc.core.api.loops import handle_tunnel_loops
            loop, kind = handle_tunnel_loops(coarse_v, coarse_t).handles[0].vertices.tolist(), "handle loop"
        except ImportError:
            loop, kind = generator_loop(coarse_v, coarse_t), "generator loop"
        fine_v, fine_t, fine_loop = loop_subdivide(coarse_v, coarse_t, loop, 3)
        bench_remove_handle(f"turbine x3 (genus 11), {kind}", fine_v, fine_t, fine_loop, args.repeats)
    else:
        print("turbine x3: skipped (../shared/meshes or ../shared/tools missing)")

    elephant = ROOT / "tests" / "data" / "open_boundary" / "cgal_elephant-with-holes.off"
    ev, et = read_off(elephant)
    print(f"elephant-with-holes: {len(ev)} vertices, {len(et)} triangles, "
          f"{len(edit.boundary_loops(ev, et))} holes")
    wall, cpu, result = timed(lambda: edit.fill_holes(ev, et), args.repeats)
    report("fill_holes (all)", wall, cpu, f"{len(result.patches)} patches")
    peer = cgal_fill(ev, et, args.repeats)
    if peer is not None:
        report("CGAL triangulate_hole, all holes", *peer,
               f"ours/CGAL wall {wall / peer[0]:.2f}, cpu {cpu / peer[1]:.2f} (CGAL excludes finding the holes)")
    else:
        print("  CGAL peer: skipped (build/peers/cgal_edit missing)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
