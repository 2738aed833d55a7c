#!/usr/bin/python3
"""Result quality next to the quadric decimators, measured in one run (issue 16 benchmark).

    .venv/bin/python tests/bench/bench_quality.py [--ratios 0.1,0.02,0.005] [--budgets 50,100,180]
                                                  [--samples 300000] [--meshes a,b] [--json FILE]

For each real mesh and each target (a ratio of its triangles, or an absolute triangle budget),
TopStoc's quality mode (the default), best mode and fast mode decimate it; every peer then decimates the
same input to the triangle count of our quality result:
  - Blender's Decimate modifier (Collapse, triangulated), in Debian's `blender -b` (one process);
  - MeshLab's meshing_decimation_quadric_edge_collapse (pymeshlab; optimal placement, preserve
    topology and boundary);
  - meshopt_simplify (build/peers/meshopt_simplify, or ${TOPSTOC_MESHOPT});
  - fast-simplification (PyPI), from a venv the benchmark makes under ${TOPSTOC_CACHE}.
Figures per output: symmetric Hausdorff max and mean in % of the input's bounding-box diagonal
(topstoc.hausdorff, the same sampling for all), triangle aspect ratio (thesis eq. 4.2) mean, 99th
percentile and worst, degenerate (zero-area) triangles, whether the topology of every component
(genus, boundary loops, manifold, orientation) was kept, and the time of the decimation itself.
Prints one table per case, then medians over the cases of our figure / the peer's figure, and
the issue-40 goals: mean error over the better of Blender and MeshLab, max error over the best peer.
A peer that is not available is reported as missing, never silently skipped.

The meshes: tests/data and ../shared/meshes (licences in tests/data/LICENSES.md and
../shared/meshes/licenses), plus the public meshes of tests/bench/quality_meshes.json (repository,
commit, path, licence, sha256), read from the cache that tests/bench/fill_mesh_cache.py fills from
local git mirrors; a mesh absent from the cache is skipped and named.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "build" / "python"))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from topstoc.core import Mesh, hausdorff, read_mesh, topology  # noqa: E402
from fill_mesh_cache import DEFAULT_CACHE as MESH_CACHE, MANIFEST, cached_path  # noqa: E402
from machine import machine  # noqa: E402
from reference import aspect_ratios  # noqa: E402
from quality_goals import PEERS, error_ratio, goal_ratios, left_out  # noqa: E402

SHARED = ROOT.parent / "shared" / "meshes"
if not SHARED.exists():
    SHARED = pathlib.Path("/work/shared/meshes")
DATA = ROOT / "tests" / "data"
LOCAL_MESHES = [
    DATA / "genus0/cgal_ChineseDragon-10kv.off",
    DATA / "genus0/cgal_fandisk.off",
    SHARED / "genus0/cgal_armadillo.off",
    SHARED / "genus0/cgal_bunny00.off",
    SHARED / "genus0/petsc_horse.ply.bz2",
    DATA / "genus_positive/cgal_turbine.off",
    DATA / "genus_positive/cgal_elephant.off",
    DATA / "genus_positive/cgal_knot1.off",
    DATA / "genus_positive/cgal_anchor_dense.off",
    DATA / "genus_positive/cgal_couplingdown.off",
    DATA / "genus_positive/cgal_double-torus-example.off",
    DATA / "genus_positive/cgal_eight.off",
    DATA / "open_boundary/cgal_mushroom.off",
    DATA / "open_boundary/cgal_elephant-with-holes.off",
    DATA / "open_boundary/kivy_suzanne_monkey.obj",
    DATA / "open_boundary/npm_teapot.obj",
    DATA / "nonmanifold_degenerate/cgal_polygon_mesh.off",
    DATA / "nonmanifold_degenerate/dragon_vrip_res4.ply.gz",
    DATA / "uv_materials/duck/duck_via_assimp.obj",
    DATA / "uv_materials/spider/spider.obj",
]


def all_meshes() -> tuple[list[pathlib.Path], list[str]]:
    """The local meshes and the manifest's cached ones, and the names of those that are absent."""
    present, absent = [], []
    for path in LOCAL_MESHES:
        (present if path.exists() else absent).append(path if path.exists() else str(path))
    for entry in json.loads(MANIFEST.read_text()):
        path = cached_path(MESH_CACHE, entry)
        (present if path.exists() else absent).append(path if path.exists() else f"{entry['repo']}:{entry['path']}")
    return present, absent
# TOPSTOC_MESHOPT names a meshopt_simplify built elsewhere (the peer needs meshoptimizer's headers)
MESHOPT = pathlib.Path(os.environ.get("TOPSTOC_MESHOPT", ROOT / "build" / "peers" / "meshopt_simplify"))
CACHE = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc"))

BLENDER_SCRIPT = r"""
import json, sys, time
import bpy, bmesh
import numpy as np
jobs = json.load(open(sys.argv[sys.argv.index("--") + 1]))
for job in jobs:
    try:
        data = np.load(job["input"])
        v, t = data["vertices"], data["triangles"]
        bpy.ops.wm.read_factory_settings(use_empty=True)
        mesh = bpy.data.meshes.new("m")
        mesh.from_pydata(v.tolist(), [], t.tolist())
        mesh.update()
        obj = bpy.data.objects.new("m", mesh)
        bpy.context.scene.collection.objects.link(obj)
        bpy.context.view_layer.objects.active = obj
        mod = obj.modifiers.new("d", "DECIMATE")
        mod.decimate_type = "COLLAPSE"
        mod.ratio = job["ratio"]
        mod.use_collapse_triangulate = True
        start = time.perf_counter()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        evaluated = obj.evaluated_get(depsgraph)
        out = evaluated.to_mesh()
        seconds = time.perf_counter() - start
        out.calc_loop_triangles()
        ov = np.empty(3 * len(out.vertices)); out.vertices.foreach_get("co", ov)
        ot = np.empty(3 * len(out.loop_triangles), dtype=np.int32); out.loop_triangles.foreach_get("vertices", ot)
        np.savez(job["output"], vertices=ov.reshape(-1, 3), triangles=ot.reshape(-1, 3), seconds=seconds)
        evaluated.to_mesh_clear()
    except Exception as error:  # the case then shows Blender as not available, named on stderr
        print(f"blender job {job['output']}: {error}", file=sys.stderr)
"""

FAST_SIMPLIFICATION_SCRIPT = r"""
import json, sys, time
import numpy as np
import fast_simplification
for job in json.load(open(sys.argv[1])):
    data = np.load(job["input"])
    start = time.perf_counter()
    v, t = fast_simplification.simplify(data["vertices"].astype(np.float32), data["triangles"].astype(np.int32),
                                        target_reduction=job["reduction"])
    seconds = time.perf_counter() - start
    np.savez(job["output"], vertices=v, triangles=t, seconds=seconds)
"""


def zero_area(vertices, triangles) -> int:
    p = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    return int(np.count_nonzero(np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1) == 0))


def signature(vertices, triangles):
    """Per surface component: (genus, boundary loops, manifold, consistently oriented), sorted."""
    top = topology(vertices, triangles)
    return sorted((c.genus if c.genus is not None else -1, len(c.boundary_loops), bool(c.manifold),
                   bool(c.consistently_oriented)) for c in top.components if c.faces > 0)


def measure(source, vertices, triangles, samples):
    if len(triangles) == 0:
        return None
    d = hausdorff(source, (vertices, triangles), samples=samples, relative=True, percentile=0)
    ar = aspect_ratios(vertices, triangles)
    finite = ar[np.isfinite(ar)]
    return {"triangles": len(triangles), "max": 100 * d.symmetric.max, "mean": 100 * d.symmetric.mean,
            "ar_mean": float(finite.mean()) if len(finite) else float("inf"),
            "ar_p99": float(np.percentile(finite, 99)) if len(finite) else float("inf"),
            "ar_max": float(finite.max()) if len(finite) else float("inf"),
            "zero_area": zero_area(vertices, triangles)}


def fast_simplification_python() -> str | None:
    """A Python with fast-simplification: this one, or a venv made once under TOPSTOC_CACHE."""
    try:
        import fast_simplification  # noqa: F401
        return sys.executable
    except ImportError:
        pass
    venv = CACHE / "venv-fast-simplification"
    python = venv / "bin" / "python"
    if not python.exists():
        try:
            subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
            subprocess.run([str(python), "-m", "pip", "install", "-q", "fast-simplification"], check=True)
        except (subprocess.CalledProcessError, OSError) as error:
            print(f"note: could not install fast-simplification ({error})")
            return None
    return str(python)


NAMES = ("topstoc quality", "topstoc best", "topstoc fast") + PEERS


def targets(triangles: int, ratios, budgets) -> list[tuple[float | None, int | None, int]]:
    """(ratio, absolute budget, target triangles) for one mesh; budgets at or above its size are left out."""
    out = [(ratio, None, max(4, int(round(ratio * triangles)))) for ratio in ratios]
    return out + [(None, budget, budget) for budget in budgets if budget < triangles]


def label(case) -> str:
    return f"{case['ratio']:.1%}" if case["ratio"] is not None else f"{case['budget']} triangles"


def run_ours(case, mesh, source, target, samples) -> None:
    for mode in ("quality", "best", "fast"):
        start = time.perf_counter()
        result = mesh.decimate(target_triangles=target, seed=0, mode=mode)
        seconds = time.perf_counter() - start
        figures = measure(source, result.vertices, result.triangles, samples)
        if figures is None:
            case["tools"][f"topstoc {mode}"] = None
            continue
        stats = result.stats
        figures.update(seconds=seconds, topology=signature(result.vertices, result.triangles) == case["signature"],
                       over_budget=int(stats.over_budget), over_budget_reason=str(stats.over_budget_reason),
                       target_missed=stats.target_missed.text() if stats.target_missed else "")
        case["tools"][f"topstoc {mode}"] = figures


def run_meshlab(case, mesh, source, samples) -> None:
    try:
        import pymeshlab
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(mesh.vertices, mesh.triangles))
        start = time.perf_counter()
        ms.meshing_decimation_quadric_edge_collapse(targetfacenum=case["peer_triangles"], optimalplacement=True,
                                                    preservetopology=True, preserveboundary=True)
        seconds = time.perf_counter() - start
        m = ms.current_mesh()
        figures = measure(source, m.vertex_matrix(), m.face_matrix(), samples)
        case["tools"]["MeshLab"] = figures and dict(
            figures, seconds=seconds, topology=signature(m.vertex_matrix(), m.face_matrix()) == case["signature"])
    except Exception as error:  # ImportError or a failing filter: shown as not available, and why
        print(f"note: MeshLab on {case['mesh']} at {label(case)}: {error}")
        case["tools"]["MeshLab"] = None


def run_meshopt(case, off, out, source, samples) -> None:
    if not MESHOPT.exists():
        case["tools"]["meshopt_simplify"] = None
        return
    done = subprocess.run([str(MESHOPT), str(off), str(out), str(3 * case["peer_triangles"])], capture_output=True,
                          text=True)
    if done.returncode != 0:
        print(f"note: meshopt_simplify on {case['mesh']}: {done.stderr.strip()}")
        case["tools"]["meshopt_simplify"] = None
        return
    got = read_mesh(out)
    figures = measure(source, got.vertices, got.triangles, samples)
    case["tools"]["meshopt_simplify"] = figures and dict(
        figures, seconds=json.loads(done.stdout).get("seconds"),
        topology=signature(got.vertices, got.triangles) == case["signature"])


def run_batched_peers(cases, blender_jobs, fs_jobs, work, samples) -> None:
    """Blender (all jobs in one process) and fast-simplification (one venv process)."""
    blender = shutil.which("blender")
    if blender:
        (work / "jobs.json").write_text(json.dumps(blender_jobs))
        (work / "blender_decimate.py").write_text(BLENDER_SCRIPT)
        subprocess.run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                        str(work / "blender_decimate.py"), "--", str(work / "jobs.json")],
                       capture_output=True, text=True, check=True)
    python = fast_simplification_python()
    if python:
        (work / "fs_jobs.json").write_text(json.dumps(fs_jobs))
        (work / "fs.py").write_text(FAST_SIMPLIFICATION_SCRIPT)
        subprocess.run([python, str(work / "fs.py"), str(work / "fs_jobs.json")], check=True)
    for case, bjob, fjob in zip(cases, blender_jobs, fs_jobs):
        for name, job, present in (("Blender Collapse", bjob, blender), ("fast-simplification", fjob, python)):
            if not present or not os.path.exists(job["output"]):
                case["tools"][name] = None
                continue
            got = np.load(job["output"])
            figures = measure(case["source"], got["vertices"], got["triangles"], samples)
            case["tools"][name] = figures and dict(
                figures, seconds=float(got["seconds"]),
                topology=signature(got["vertices"], got["triangles"]) == case["signature"])


def print_case(case) -> None:
    print(f"\n{case['mesh']} at {label(case)} ({case['input_triangles']} triangles -> "
          f"peers at {case['peer_triangles']})")
    print(f"  {'tool':21s} {'tris':>6s} {'max %':>7s} {'mean %':>8s} {'AR mean':>8s} {'AR p99':>8s} "
          f"{'AR max':>8s} {'zero':>4s} {'topo':>4s} {'s':>7s}")
    for name in NAMES:
        f = case["tools"].get(name)
        if f is None:
            print(f"  {name:21s} (not available)")
            continue
        seconds = f"{f['seconds']:.3f}" if f.get("seconds") is not None else "-"
        over = f"  {f['target_missed']}" if f.get("target_missed") else ""
        print(f"  {name:21s} {f['triangles']:6d} {f['max']:7.3f} {f['mean']:8.4f} {f['ar_mean']:8.3f} "
              f"{f['ar_p99']:8.2f} {f['ar_max']:8.1f} {f['zero_area']:4d} {'yes' if f['topology'] else 'NO':>4s} "
              f"{seconds:>7s}{over}")
    mean, worst = goal_ratios(case)
    if left_out(case):
        print(f"  stopped above our count, left out of the goals: {', '.join(left_out(case))}")
    if mean is not None or worst is not None:
        fair = [f"{v:.3f}" if v is not None else "-" for v in goal_ratios(case, kept_topology=True)]
        print(f"  quality mean / better of Blender, MeshLab: {mean if mean is not None else float('nan'):.3f}; "
              f"max / best peer: {worst if worst is not None else float('nan'):.3f}; "
              f"only peers that kept the topology: {fair[0]}, {fair[1]}")


def summarize(cases) -> None:
    print("\nMedians over the cases of topstoc quality / peer (below 1: ours is better), worst case in brackets:")
    for name in PEERS:
        pairs = [(c["tools"]["topstoc quality"], c["tools"][name]) for c in cases
                 if c["tools"].get(name) and c["tools"].get("topstoc quality")]
        if not pairs:
            print(f"  {name}: not available")
            continue
        parts = []
        for key in ("mean", "max", "ar_mean", "ar_max"):
            values = [error_ratio(a[key], b[key]) for a, b in pairs]
            parts.append(f"{key} {statistics.median(values):.3f} [{max(values):.2f}]")
        parts.append(f"peer keeps topology {sum(b['topology'] for _, b in pairs)}/{len(pairs)}")
        print(f"  vs {name}: " + ", ".join(parts))
    ours = [c["tools"]["topstoc quality"] for c in cases if c["tools"].get("topstoc quality")]
    print(f"  topstoc quality keeps topology {sum(o['topology'] for o in ours)}/{len(ours)}, "
          f"zero-area triangles {sum(o['zero_area'] for o in ours)}, over budget in "
          f"{sum(bool(o.get('over_budget')) for o in ours)}")
    goals = (("mean / better of Blender and MeshLab", 0.9, 1.0), ("max / best peer", 1.0, 1.15))
    for mode, kept, index in ((m, k, i) for m in ("quality", "best") for k in (False, True) for i in range(2)):
        what, goal_median, goal_every = goals[index]
        what = f"{mode}: {what}" + (" that kept the topology" if kept else "")
        ranked = sorted(((ratio, c) for c in cases if (ratio := goal_ratios(c, mode, kept)[index]) is not None),
                        key=lambda pair: pair[0])
        if not ranked:
            continue
        values = [v for v, _ in ranked]
        worst, case = ranked[-1]
        print(f"  {what}: median {statistics.median(values):.3f} (goal <= {goal_median}), worst {worst:.2f} "
              f"({case['mesh']} at {label(case)}), above {goal_every} in {sum(v > goal_every for v in values)}"
              f"/{len(values)} (goal 0); no such peer at our count in {len(cases) - len(values)}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ratios", default="0.1,0.02,0.005")
    parser.add_argument("--budgets", default="50,100,180", help="absolute triangle budgets ('' for none)")
    parser.add_argument("--samples", type=int, default=300_000, help="Hausdorff samples on the input")
    parser.add_argument("--meshes", default="", help="comma-separated name fragments to run only those")
    parser.add_argument("--json", metavar="FILE", help="write every figure here")
    args = parser.parse_args()
    ratios = [float(r) for r in args.ratios.split(",") if r]
    budgets = [int(b) for b in args.budgets.split(",") if b]
    present, absent = all_meshes()
    meshes = [m for m in present if not args.meshes or any(f in m.name for f in args.meshes.split(","))]
    print(f"machine: {machine()}")
    print(f"meshes: {len(meshes)} ({', '.join(m.name for m in meshes)}); ratios {ratios}; budgets {budgets}; "
          f"Hausdorff samples {args.samples}")
    if absent:
        print(f"skipped, not in the cache (tests/bench/fill_mesh_cache.py fills it): {', '.join(absent)}")
    work = pathlib.Path(tempfile.mkdtemp(prefix="bench_quality_"))
    cases, blender_jobs, fs_jobs = [], [], []
    for path in meshes:
        try:
            data = read_mesh(path)
            mesh = Mesh(data.vertices, data.triangles)
        except Exception as error:  # an unreadable input is named, the others still run
            print(f"skipped {path.name}: {error}")
            continue
        source = (mesh.vertices, mesh.triangles)
        source_signature = signature(*source)
        stem = f"{path.parent.name}_{path.stem}"
        np.savez(work / f"{stem}.npz", vertices=mesh.vertices, triangles=mesh.triangles)
        off = work / f"{stem}.off"
        with open(off, "w") as handle:
            handle.write(f"OFF\n{len(mesh.vertices)} {len(mesh.triangles)} 0\n")
            np.savetxt(handle, mesh.vertices, fmt="%.17g")
            np.savetxt(handle, np.column_stack([np.full(len(mesh.triangles), 3), mesh.triangles]), fmt="%d")
        for ratio, budget, target in targets(len(mesh.triangles), ratios, budgets):
            case = {"mesh": path.name, "ratio": ratio, "budget": budget, "target": target,
                    "input_triangles": len(mesh.triangles), "tools": {}, "source": source,
                    "signature": source_signature}
            run_ours(case, mesh, source, target, args.samples)
            if case["tools"]["topstoc quality"] is None:
                print(f"skipped {path.name} at {label(case)}: empty quality result")
                continue
            ours = case["peer_triangles"] = case["tools"]["topstoc quality"]["triangles"]
            key = f"{stem}_{ratio if ratio is not None else budget}"
            blender_jobs.append({"input": str(work / f"{stem}.npz"), "output": str(work / f"{key}_blender.npz"),
                                 "ratio": ours / len(mesh.triangles)})
            fs_jobs.append({"input": str(work / f"{stem}.npz"), "output": str(work / f"{key}_fs.npz"),
                            "reduction": 1.0 - ours / len(mesh.triangles)})
            run_meshlab(case, mesh, source, args.samples)
            run_meshopt(case, off, work / f"{key}_meshopt.off", source, args.samples)
            cases.append(case)
            print(f"done {path.name} at {label(case)}", flush=True)
    run_batched_peers(cases, blender_jobs, fs_jobs, work, args.samples)
    shutil.rmtree(work, ignore_errors=True)
    for case in cases:
        print_case(case)
    summarize(cases)
    if args.json:  # read by scripts/benchmarks_md.py (docs/bench_results/*.json)
        for case in cases:
            case.pop("source", None)
        pathlib.Path(args.json).write_text(json.dumps(
            {"benchmark": "tests/bench/bench_quality.py", "machine": machine(),
             "date": time.strftime("%Y-%m-%d", time.gmtime()), "samples": args.samples, "skipped": absent,
             "cases": cases}, indent=1, default=str) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
