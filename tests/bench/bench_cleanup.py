"""Benchmark: the topology clean-up (topstoc.core.api.clean) on meshes with many small defects.

    /usr/bin/python3 tests/bench/bench_cleanup.py [--handles 10,100,300] [--holes 50,300,1000]
    /usr/bin/python3 tests/bench/bench_cleanup.py --handles 10,100 --holes 50,1000 --scan --json FILE
    /usr/bin/python3 tests/bench/bench_cleanup.py --speed 1000:0,1000:2 [--baseline DIR] [--json FILE]

Cases (tests/cleanup_meshes.py, positions jittered by 0.05 like a scan):
  * block + k small arches + 4 large ones: genus k + 4; the small handles' loops are 4 long,
    the large ones' 12; size 6. Figures: genus before/after, handles left above the size, loops
    left below it (recomputed on the output), worst patch aspect (R / 2r), area changed, time.
    Anchor: a voxel remesh at the same detail (MeshLab's uniform resampling, marching cubes on
    cells one mean edge long): the genus it leaves and the area it changes; PyMeshFix's repair.
  * plate with k 2 x 2-quad holes (border 8) and 4 large ones (border 16); size 10. Figures: holes
    left, worst patch aspect, the patches' largest distance from the plate's plane, input
    triangles kept bit for bit, time; PyMeshFix (fill_small_boundaries, up to 10 boundary edges)
    and MeshLab (Close Holes, up to 10 edges, refined) on the same input.
  * --scan: the Stanford armadillo (tests/data) with 8 pinched handles added, size 1 %; the voxel
    remesh at its median edge length beside it.
  * the same blocks subdivided once and Taubin-smoothed: organic little handles (loops about
    3.2, the large ones 11; size 5), where the faired caps are kept.
  * the criterion: on the elephant (tests/data, holes filled) and on unit arches, each handle
    loop and each tunnel loop crossing it removed apart: does the shorter one give the smaller
    patch area?
  * --speed K:L: the block with K small arches (and 4 large), subdivided L times (1000:2 is
    1,200,128 triangles: the issue's 1,000 handles on a 1M-triangle mesh), cleaned in a child
    process: wall and CPU seconds (TetGen's forked children included), genus, loops left below
    the size on the output (computed again, not timed), patch styles; --baseline DIR times
    another build's python directory the same way (--baseline-cases: only those); --json FILE
    saves the figures for scripts/benchmarks_md.py.
  * the criterion: on the elephant (tests/data, holes filled) and on unit arches, each handle
    loop and each tunnel loop crossing it removed apart: does the shorter one give the smaller
    patch area?

The peers run in their own Pythons: TOPSTOC_PYMESHFIX_PYTHON (a venv with ``pip install
pymeshfix``; default /tmp/clean-venv/bin/python) and TOPSTOC_PYMESHLAB_PYTHON (default the
project's .venv, which has pymeshlab); a peer that is not there is left out (a dash).
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import resource
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = os.environ.get("TOPSTOC_BENCH_BUILD", str(ROOT / "build" / "python"))  # --baseline's child sets it
sys.path[:0] = [BUILD, str(ROOT / "tests"), str(ROOT / "tests" / "bench")]

import cleanup_meshes  # noqa: E402
import meshgen  # noqa: E402
import reference  # noqa: E402
from machine import machine, save_figures  # noqa: E402
from topstoc.core.api import edit  # noqa: E402
from topstoc.core.api.clean import clean, patch_quality  # noqa: E402
from topstoc.core.api.io import read_mesh  # noqa: E402
from topstoc.core.api.loops import handle_tunnel_loops  # noqa: E402
from topstoc.core.api.topology import topology  # noqa: E402

SIZE = 6.0
HOLE_SIZE = 10.0
PYMESHFIX = os.environ.get("TOPSTOC_PYMESHFIX_PYTHON", "/tmp/clean-venv/bin/python")
PYMESHLAB = os.environ.get("TOPSTOC_PYMESHLAB_PYTHON", str(ROOT / ".venv" / "bin" / "python"))

# Run in the PyMeshFix venv: reads in.npz, writes out.npz with the result and its time.
PEER = """
import sys, time, numpy as np, pymeshfix
data = np.load(sys.argv[1]); v, f = data["v"], data["f"].astype(np.int32)
start = time.perf_counter()
if sys.argv[3] == "fill":
    mesh = pymeshfix.PyTMesh(); mesh.set_quiet(True); mesh.load_array(v, f)
    mesh.fill_small_boundaries(nbe=10, refine=True)
    v2, f2 = mesh.return_arrays()
else:
    fix = pymeshfix.MeshFix(v, f); fix.repair(); v2, f2 = fix.points, fix.faces
np.savez(sys.argv[2], v=v2, f=f2, seconds=time.perf_counter() - start)
"""


# Run in the pymeshlab venv: "fill" closes holes of up to argv[4] edges (refined), "voxel"
# resamples on a grid of cell argv[4] (marching cubes: MeshLab's Uniform Mesh Resampling).
MESHLAB = """
import sys, time, numpy as np, pymeshlab
data = np.load(sys.argv[1])
ms = pymeshlab.MeshSet(); ms.add_mesh(pymeshlab.Mesh(data["v"], data["f"].astype(np.int32)))
start = time.perf_counter()
if sys.argv[3] == "fill":
    ms.meshing_close_holes(maxholesize=int(sys.argv[4]), refinehole=True)
else:
    ms.generate_resampled_uniform_mesh(cellsize=pymeshlab.PureValue(float(sys.argv[4])),
                                       offset=pymeshlab.PureValue(0.0), mergeclosevert=True)
seconds = time.perf_counter() - start
m = ms.current_mesh()
np.savez(sys.argv[2], v=m.vertex_matrix(), f=m.face_matrix(), seconds=seconds)
"""


def peer(vertices, triangles, mode: str, python: str = PYMESHFIX, script: str = PEER, *extra):
    """A peer's result (vertices, triangles, seconds), or None when its Python is not there."""
    if not pathlib.Path(python).exists():
        return None
    with tempfile.TemporaryDirectory() as tmp:
        source, target = pathlib.Path(tmp, "in.npz"), pathlib.Path(tmp, "out.npz")
        np.savez(source, v=vertices, f=triangles)
        subprocess.run([python, "-c", script, str(source), str(target), mode, *map(str, extra)], check=True)
        out = np.load(target)
        return out["v"], out["f"], float(out["seconds"])


def area(vertices, triangles) -> float:
    q = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    return float(0.5 * np.linalg.norm(np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]), axis=1).sum())


def voxel_anchor(vertices, triangles, cell: float):
    """MeshLab's voxel remesh at cell ``cell``: {genus, area_change, triangles, seconds} or None."""
    out = peer(vertices, triangles, "voxel", PYMESHLAB, MESHLAB, cell)
    if out is None:
        return None
    return {"genus": genus(out[0], out[1]), "area_change": area(out[0], out[1]) / area(vertices, triangles) - 1,
            "triangles": int(len(out[1])), "kept": kept_bit_for_bit(vertices, triangles, out[0], out[1]),
            "seconds": out[2]}


def mean_edge(vertices, triangles) -> float:
    t = np.asarray(triangles, dtype=np.int64)
    return float(np.linalg.norm(vertices[t[:, 0]] - vertices[t[:, 1]], axis=1).mean())


def genus(vertices, triangles) -> int:
    return sum(c.genus or 0 for c in topology(vertices, triangles).components if c.kind == "surface")


def kept_bit_for_bit(vertices, triangles, out_vertices, out_triangles) -> float:
    """Fraction of input triangles found in the output with exactly the same corner positions
    (any vertex numbering, any rotation of the corners)."""
    def keys(v, t):
        p = np.ascontiguousarray(v[np.asarray(t, dtype=np.int64)])
        rows = p.reshape(len(t), 3, 3).view(np.dtype((np.void, 24))).reshape(len(t), 3)
        return {frozenset(r.tobytes() for r in row) for row in rows}
    before, after = keys(vertices, triangles), keys(out_vertices, out_triangles)
    return len(before & after) / len(before)


def created(vertices, triangles, out_vertices, out_triangles):
    """(worst aspect of the output triangles that are not input triangles, largest |z| of the
    output vertices that are not input vertices), matched by positions."""
    p = np.ascontiguousarray(vertices[np.asarray(triangles, dtype=np.int64)]).reshape(len(triangles), 9)
    old = {frozenset(map(bytes, row.reshape(3, 3))) for row in p}
    q = np.ascontiguousarray(out_vertices[np.asarray(out_triangles, dtype=np.int64)]).reshape(len(out_triangles), 9)
    new = np.array([frozenset(map(bytes, row.reshape(3, 3))) not in old for row in q])
    aspect = float(reference.aspect_ratios(out_vertices, out_triangles[new]).max()) if new.any() else 1.0
    points = {bytes(row) for row in np.ascontiguousarray(vertices)}
    fresh = np.array([bytes(row) not in points for row in np.ascontiguousarray(out_vertices)])
    return aspect, float(np.abs(out_vertices[fresh, 2]).max()) if fresh.any() else 0.0, int(fresh.sum())


def handles_row(name: str, vertices, triangles, size, voxel_cell: float) -> dict:
    """Ours on one mesh with small handles, the voxel anchor and PyMeshFix's repair beside it."""
    start = time.perf_counter()
    result = clean(vertices, triangles, max_handle=size, max_hole=0)
    seconds = time.perf_counter() - start
    loops = handle_tunnel_loops(result.vertices, result.triangles)
    row = {"case": name, "triangles": int(len(triangles)), "genus_before": result.genus_before,
           "genus_after": result.genus_after, "removed": result.count("handle") + result.count("tunnel"),
           "loops_below_size": sum(1 for loop in loops.handles + loops.tunnels if loop.length < result.max_handle),
           "rounds": result.rounds, "patch_aspect": result.patch_aspect,
           "area_change": area(result.vertices, result.triangles) / area(vertices, triangles) - 1,
           "kept": kept_bit_for_bit(vertices, triangles, result.vertices, result.triangles),
           "seconds": seconds, "loops_seconds": result.seconds.get("loops", 0.0),
           "voxel": voxel_anchor(vertices, triangles, voxel_cell), "voxel_cell": voxel_cell}
    fixed = peer(vertices, triangles, "repair")
    row["pymeshfix_genus"] = None if fixed is None else genus(fixed[0], fixed[1])
    voxel = row["voxel"]
    print(f"{name}: {row['triangles']} triangles, genus {row['genus_before']} -> {row['genus_after']} "
          f"(loops left below the size: {row['loops_below_size']}), removed {row['removed']} in {row['rounds']} rounds, "
          f"patch aspect <= {row['patch_aspect']:.2f}, area {100 * row['area_change']:+.3f} %, input triangles kept "
          f"{100 * row['kept']:.1f} %, {seconds:.2f} s (loops {row['loops_seconds']:.2f} s)")
    if voxel is not None:
        print(f"  voxel remesh (MeshLab, cell {voxel_cell:.3g}): genus {voxel['genus']}, area {100 * voxel['area_change']:+.2f} % "
              f"({abs(voxel['area_change']) / max(abs(row['area_change']), 1e-12):.0f}x ours), input triangles kept "
              f"{100 * voxel['kept']:.1f} %, {voxel['seconds']:.2f} s")
    if fixed is not None:
        print(f"  PyMeshFix repair: genus {row['pymeshfix_genus']}")
    return row


def bench_handles(k: int, smooth: bool = False) -> dict:
    vertices, triangles = cleanup_meshes.block_with_arches(k, 4, jitter=0.0 if smooth else 0.05, seed=k)
    size = SIZE
    if smooth:  # subdivided and smoothed: organic little handles, loops about 3.2 (large ones 11)
        vertices, triangles = meshgen.subdivide(vertices, triangles, 1)
        vertices, size = cleanup_meshes.smoothed(vertices, triangles), 5.0
    name = f"{k} arches{' smoothed' if smooth else ''}"
    return handles_row(name, vertices, triangles, size, mean_edge(vertices, triangles))


def bench_scan() -> dict:
    """The armadillo scan with 8 pinched handles (the GUI test's input), size 1 %."""
    data = read_mesh(str(ROOT / "tests" / "data" / "genus0" / "cgal_armadillo.off.gz"))
    vertices, triangles, _arches = cleanup_meshes.with_pinched_handles(data.vertices, data.triangles, 8, seed=1)
    cell = float(np.median(np.linalg.norm(vertices[triangles[:, 0]] - vertices[triangles[:, 1]], axis=1)))
    return handles_row("armadillo scan + 8 pinched handles", vertices, triangles, "1%", cell)


def fill_figures(vertices, triangles, out_vertices, out_triangles, seconds) -> dict:
    """A hole filler's output on the plate: borders left, patch aspect, rise, triangles kept."""
    aspect, rise, added = created(vertices, triangles, out_vertices, out_triangles)
    return {"borders_after": len(edit.boundary_loops(out_vertices, out_triangles)), "patch_aspect": aspect,
            "rise": rise, "added_vertices": added, "seconds": seconds,
            "kept": kept_bit_for_bit(vertices, triangles, out_vertices, out_triangles)}


def bench_holes(k: int) -> dict:
    side = int(np.ceil(3 * np.sqrt(1.4 * k))) + 16
    vertices, triangles = cleanup_meshes.perforated_plate(k, 4, side=side, small_size=2, jitter=0.05, seed=k)
    holes = len(edit.boundary_loops(vertices, triangles))
    start = time.perf_counter()
    result = clean(vertices, triangles, max_hole=HOLE_SIZE, max_handle=0)
    seconds = time.perf_counter() - start
    row = {"k": k, "triangles": int(len(triangles)), "borders_before": holes,
           "ours": fill_figures(vertices, triangles, result.vertices, result.triangles, seconds)}
    row["ours"]["patch_aspect"] = result.patch_aspect  # the patches' own (created() matches by position)
    for name, python, script, mode, extra in (("pymeshfix", PYMESHFIX, PEER, "fill", ()),
                                              ("meshlab", PYMESHLAB, MESHLAB, "fill", (10,))):
        out = peer(vertices, triangles, mode, python, script, *extra)
        row[name] = None if out is None else fill_figures(vertices, triangles, *out)
    for name in ("ours", "pymeshfix", "meshlab"):
        f = row[name]
        if f is None:
            print(f"  {name}: not installed")
            continue
        print(f"holes k={k} {name}: {holes} borders -> {f['borders_after']}, patch aspect <= {f['patch_aspect']:.2f}, "
              f"{f['added_vertices']} vertices added, <= {f['rise']:.3f} off the plane, input triangles kept "
              f"{100 * f['kept']:.1f} %, {f['seconds']:.3f} s"
              + ("" if name == "ours" else f" (aspect ours / theirs {row['ours']['patch_aspect'] / f['patch_aspect']:.2f}, "
                                            f"time theirs / ours {f['seconds'] / row['ours']['seconds']:.2f})"))
    return row


def removal_area(vertices, triangles, loop):
    """Patch area of removing the handle along ``loop`` (faired), or None when it fails."""
    try:
        result = edit.remove_handle(vertices, triangles, loop.vertices, refine=True, fair=True)
    except ValueError:
        return None
    return patch_quality(result.vertices, result.triangles, result.patches)[0]


def bench_criterion(name: str, vertices, triangles) -> None:
    """Does the shorter of a handle's two loops also give the smaller patches? Each handle loop
    is paired with the tunnel loops it crosses (shares a vertex with); both are removed apart."""
    found = handle_tunnel_loops(vertices, triangles)
    agree = total = 0
    for handle in found.handles:
        for tunnel in found.tunnels:
            if not np.intersect1d(handle.vertices, tunnel.vertices).size:
                continue
            areas = [removal_area(vertices, triangles, loop) for loop in (handle, tunnel)]
            short, long = (0, 1) if handle.length <= tunnel.length else (1, 0)
            total += 1
            agree += areas[short] is not None and (areas[long] is None or areas[short] <= areas[long])
            print(f"  {name}: handle loop {handle.length:.4g} -> patch area "
                  f"{'failed' if areas[0] is None else format(areas[0], '.4g')}, tunnel loop {tunnel.length:.4g} "
                  f"-> {'failed' if areas[1] is None else format(areas[1], '.4g')}")
    print(f"criterion on {name}: the shorter loop gave the smaller patch (or the only one) in {agree} of {total} pairs")


def cpu_seconds() -> float:
    """CPU time of this process and its finished children (TetGen runs in a forked child)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def speed_case(case: str) -> dict:
    """One --speed case ("K:L"), cleaned in this process: the figures as a dict."""
    k, levels = (int(x) for x in case.split(":"))
    vertices, triangles = cleanup_meshes.block_with_arches(k, 4, jitter=0.05, seed=k)
    vertices, triangles = meshgen.subdivide(vertices, triangles, levels) if levels else (vertices, triangles)
    wall, cpu = time.perf_counter(), cpu_seconds()
    result = clean(vertices, triangles, max_handle=SIZE, max_hole=0)
    wall, cpu = time.perf_counter() - wall, cpu_seconds() - cpu
    loops = handle_tunnel_loops(result.vertices, result.triangles)
    styles = {}
    for item in result.removed:
        styles[item.patch] = styles.get(item.patch, 0) + 1
    return {"case": case, "small_arches": k, "subdivisions": levels, "triangles": len(triangles),
            "genus_before": result.genus_before, "genus_after": result.genus_after,
            "removed": len(result.removed), "rounds": result.rounds,
            "loops_left_below": sum(1 for loop in loops.handles + loops.tunnels if loop.length < SIZE),
            "patch_aspect": result.patch_aspect, "styles": styles, "wall": wall, "cpu": cpu,
            "loops_wall": result.seconds.get("loops", 0.0)}


def speed_in_child(case: str, build: str) -> dict:
    """speed_case in a child process with the python package of ``build``."""
    out = subprocess.run([sys.executable, __file__, "--child", case], check=True, capture_output=True, text=True,
                         env={**os.environ, "TOPSTOC_BENCH_BUILD": build})
    return json.loads(out.stdout.splitlines()[-1])


def speed(args) -> int:
    """--speed: each case with this build (and --baseline's), printed and saved with --json."""
    print(machine(), flush=True)
    rows = []
    for case in args.speed.split(","):
        row = speed_in_child(case, BUILD)
        if args.baseline and (args.baseline_cases is None or case in args.baseline_cases.split(",")):
            row["baseline"] = speed_in_child(case, args.baseline)
        rows.append(row)
        was = (f"; before: {row['baseline']['wall']:.1f} s wall, {row['baseline']['cpu']:.1f} s CPU"
               if "baseline" in row else "")
        print(f"{row['small_arches']} arches, {row['subdivisions']} subdivisions: {row['triangles']:,} triangles, "
              f"genus {row['genus_before']} -> {row['genus_after']}, {row['removed']} removed in {row['rounds']} "
              f"round(s), loops left below the size {row['loops_left_below']}, patch aspect <= "
              f"{row['patch_aspect']:.2f}, {row['styles']}: {row['wall']:.1f} s wall, {row['cpu']:.1f} s CPU "
              f"(loops {row['loops_wall']:.1f} s wall){was}", flush=True)
    if args.json:
        save_figures(args.json, "tests/bench/bench_cleanup.py --speed",
                     "clean(vertices, triangles, max_handle=6, max_hole=0) once per case in a child process, wall "
                     "and CPU seconds (the process and its TetGen children); "
                     + (f"the baseline is {args.baseline} timed the same way in the same run" if args.baseline
                        else "no baseline"), cases=rows)
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--handles", default="10,100,300", help="small handle counts, comma-separated")
    parser.add_argument("--smooth", default="10,100", help="small handle counts on smoothed blocks")
    parser.add_argument("--holes", default="50,300,1000", help="small hole counts, comma-separated")
    parser.add_argument("--speed", help="only time these cases K:L (K small arches, L subdivisions), comma-separated")
    parser.add_argument("--baseline", help="with --speed: another build's python directory, timed alongside")
    parser.add_argument("--baseline-cases", help="with --baseline: only these cases (default: all)")
    parser.add_argument("--scan", action="store_true", help="also the armadillo scan with pinched handles")
    parser.add_argument("--no-criterion", action="store_true", help="skip the loop-choice criterion")
    parser.add_argument("--json", help="save the figures here (with --speed: the speed figures)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(speed_case(args.child)))
        return 0
    if args.speed:
        return speed(args)
    print(machine())
    handles = [bench_handles(k) for k in (int(x) for x in args.handles.split(",") if x)]
    handles += [bench_handles(k, smooth=True) for k in (int(x) for x in args.smooth.split(",") if x)]
    handles += [bench_scan()] if args.scan else []
    holes = [bench_holes(k) for k in (int(x) for x in args.holes.split(",") if x)]
    if args.json:
        save_figures(args.json, "tests/bench/bench_cleanup.py",
                     "tests/cleanup_meshes.py blocks with k unit arches and 4 large ones (size 6), smoothed ones "
                     "(size 5), plates with k small holes (size 10); the armadillo scan with 8 pinched handles "
                     "(size 1 %); peers in the same run: MeshLab (pymeshlab) Close Holes and Uniform Mesh "
                     "Resampling at one mean edge, PyMeshFix fill_small_boundaries(10) and repair",
                     handles=handles, holes=holes)
    if args.no_criterion:
        return 0
    elephant = read_mesh(str(ROOT / "tests" / "data" / "open_boundary" / "cgal_elephant-with-holes.off"))
    filled = edit.fill_holes(elephant.vertices, elephant.triangles, refine=True, fair=True)
    bench_criterion("elephant (holes filled)", filled.vertices, filled.triangles)
    v, t = cleanup_meshes.block_with_arches(6, 0, jitter=0.05, seed=1)
    bench_criterion("6 unit arches", v, t)
    return 0


if __name__ == "__main__":
    sys.exit(main())
