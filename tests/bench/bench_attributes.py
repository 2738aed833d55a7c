#!/usr/bin/python3
"""The look after decimation next to meshoptimizer's and Blender's, in one run (issue 40, item 3).

    python3 tests/bench/bench_attributes.py [--ratios 0.1,0.02] [--samples 50000] [--assets a,b] [--json FILE]

For each asset and ratio, TopStoc's quality mode decimates it with its look in the cost (the public
API as the add-on calls it: topstoc.core.carry.appearance's attributes at ATTRIBUTE_WEIGHT, UV seams
and hard normal edges as borders, the attributes carried through the result's source maps and then
fitted to the source's by least squares, carry.look_fit); every
peer then decimates the same asset to our triangle count:
  - meshopt_simplifyWithAttributes (meshoptimizer 0.22 from PyPI's `meshoptimizer` 0.2.30a0, in a
    venv made once under ${TOPSTOC_CACHE}), on the asset split into one vertex per distinct
    (position, UV, normal, colour), weights 1 for UVs and colours and 0.5 for normals (meshoptimizer's
    demo); its output vertices are input vertices, attributes and all;
  - Blender's Decimate modifier (Collapse, triangulated), bpy 4.2 (${TOPSTOC_BPY_PYTHON}, default
    /work/main/.venv/bin/python), the asset as a Blender mesh with a UV map, custom split normals
    and a point colour attribute; the result's UVs, corner normals and colours as Blender gives them.
The errors (tests/attribute_error.py): per point sampled on the result and on the source, the
difference between the result's interpolated value and the source's at the closest point; mean
over both directions. UV in texture units, normal in degrees, colour as RGB distance in [0, 1]
units. Printed per case with our figure over each peer's; then medians and worst over the cases.
Each output's symmetric mean distance to the source (topstoc.hausdorff, % of the diagonal) is
printed beside them: where the geometry drifts, so does the look.

Assets (licences in tests/data/LICENSES.md and ../shared/meshes/licenses):
  - duck: tests/data/uv_materials/duck (UVs, the file's normals), one component;
  - spider: tests/data/uv_materials/spider (UVs with many islands, the file's normals), 19 parts;
  - suzanne: tests/data/open_boundary/kivy_suzanne_monkey.obj (the file's normals, open);
  - painted dragon: tests/data/genus0/cgal_ChineseDragon-10kv.off with a procedural colour
    (smooth bands and one sharp stripe per vertex, PAINT below);
  - capped cylinder: tests/capped_cylinder.py (hard rims, normals faking a bevel).
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import pathlib
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

from topstoc.core import Mesh, hausdorff  # noqa: E402
from topstoc.core.api.decimate import ATTRIBUTE_WEIGHT  # noqa: E402
from topstoc.core.api.hausdorff import closest_points  # noqa: E402
from topstoc.core.api.io import read_mesh  # noqa: E402
from topstoc.core.carry.appearance import appearance_attributes, unit_corner_normals  # noqa: E402
from topstoc.core.carry.look_fit import fit_look  # noqa: E402
from topstoc.core.carry.attributes import corner_values, hard_normal_edges, moved_vertices, uv_seam_edges  # noqa: E402
from attribute_error import CHANNELS, attribute_errors  # noqa: E402
from capped_cylinder import capped_cylinder  # noqa: E402
from machine import machine  # noqa: E402

DATA = ROOT / "tests" / "data"
CACHE = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc"))
BPY_PYTHON = os.environ.get("TOPSTOC_BPY_PYTHON", "/work/main/.venv/bin/python")
MESHOPT_WEIGHTS = {"uv": 1.0, "normal": 0.5, "color": 1.0}
PEERS = ("meshopt_simplifyWithAttributes", "Blender Collapse")


# -- the assets --------------------------------------------------------------------------------

def obj_corner_normals(path: pathlib.Path, triangles: np.ndarray) -> np.ndarray:
    """(m, 3, 3) the OBJ's vn per triangle corner, fanned as io.read_mesh fans its faces (checked
    against ``triangles``)."""
    normals, corners, positions = [], [], []
    for line in path.read_text().splitlines():
        words = line.split()
        if words and words[0] == "vn":
            normals.append([float(x) for x in words[1:4]])
        elif words and words[0] == "f" and len(words) >= 4:
            ref = [w.split("/") for w in words[1:]]
            for k in range(1, len(ref) - 1):
                fan = (ref[0], ref[k], ref[k + 1])
                positions.append([int(r[0]) - 1 for r in fan])
                corners.append([int(r[2]) - 1 for r in fan])
    if not np.array_equal(np.array(positions), triangles):
        raise SystemExit(f"error: {path}: the faces do not fan as io.read_mesh fans them")
    return unit_corner_normals(triangles, np.array(normals)[np.array(corners)])  # zero-length ones filled


# A colour per vertex: smooth bands in each channel and one sharp stripe, so both a gradient and an
# edge in the paint must survive.
PAINT = {"frequency": (3.0, 5.0, 7.0), "stripe": (0.45, 0.55)}


def paint(vertices: np.ndarray) -> np.ndarray:
    """(n, 3) the procedural colour of the painted asset (PAINT), from positions in its box."""
    unit = (vertices - vertices.min(0)) / np.ptp(vertices, axis=0).max()
    rgb = 0.5 + 0.5 * np.sin(2 * np.pi * unit * np.array(PAINT["frequency"]))
    stripe = (unit[:, 0] > PAINT["stripe"][0]) & (unit[:, 0] < PAINT["stripe"][1])
    rgb[stripe] = (0.9, 0.1, 0.1)
    return rgb


def _obj_asset(name: str, path: pathlib.Path) -> dict:
    data = read_mesh(path)
    return {"name": name, "vertices": data.vertices, "triangles": data.triangles.astype(np.int64),
            "uv": data.corner_uvs, "normal": obj_corner_normals(path, data.triangles)}


def _painted_dragon() -> dict:
    dragon = read_mesh(DATA / "genus0/cgal_ChineseDragon-10kv.off")
    triangles = dragon.triangles.astype(np.int64)
    return {"name": "painted dragon", "vertices": dragon.vertices, "triangles": triangles,
            "color": paint(dragon.vertices)[triangles]}


def _capped_cylinder() -> dict:
    vertices, triangles, normals = capped_cylinder()
    return {"name": "capped cylinder", "vertices": vertices, "triangles": triangles, "normal": normals}


ASSETS = {
    "duck": lambda: _obj_asset("duck", DATA / "uv_materials/duck/duck_via_assimp.obj"),
    "spider": lambda: _obj_asset("spider", DATA / "uv_materials/spider/spider.obj"),
    "suzanne": lambda: _obj_asset("suzanne", DATA / "open_boundary/kivy_suzanne_monkey.obj"),
    "painted dragon": _painted_dragon,
    "capped cylinder": _capped_cylinder,
}


def assets(names) -> list[dict]:
    """The assets ``names`` (all when empty; module docs) as dicts of tests/attribute_error.py, plus "name"."""
    unknown = [n for n in names if n not in ASSETS]
    if unknown:
        raise SystemExit(f"error: unknown assets {unknown}; known: {', '.join(ASSETS)}")
    return [load() for name, load in ASSETS.items() if not names or name in names]


# -- TopStoc -----------------------------------------------------------------------------------

def target_triangles(asset: dict, ratio: float) -> int:
    return max(4, round(ratio * len(asset["triangles"])))


def run_ours(asset: dict, ratio: float, weight: float = ATTRIBUTE_WEIGHT) -> tuple[dict, float]:
    """Quality mode with the look in the cost, seams and hard edges as borders; attributes carried
    and fitted to the source's (carry.look_fit, as the add-on writes them); the seconds count both."""
    t = asset["triangles"]
    look = appearance_attributes(t, asset.get("uv"), asset.get("color"), asset.get("normal"))
    borders = [np.zeros((0, 2), dtype=np.int64)]
    if asset.get("uv") is not None:
        borders.append(uv_seam_edges(t, asset["uv"]))
    if asset.get("normal") is not None:
        borders.append(hard_normal_edges(t, asset["normal"]))
    start = time.perf_counter()
    result = Mesh(asset["vertices"], t).decimate(target_triangles=target_triangles(asset, ratio),
                                                 borders=np.concatenate(borders).astype(np.int64),
                                                 **look.decimate_kwargs(weight))
    moved = moved_vertices(asset["vertices"], t, result)
    out = {"vertices": result.vertices, "triangles": np.asarray(result.triangles, dtype=np.int64)}
    m = len(t)
    for channel in CHANNELS:
        if asset.get(channel) is not None:
            values = asset[channel].reshape(3 * m, -1)
            flat = corner_values(values, result.corner_source, result.triangles, moved, np.arange(3 * m).reshape(m, 3))
            out[channel] = flat.reshape(-1, 3, values.shape[1])
    channels = [c for c in CHANNELS if out.get(c) is not None]
    fitted = fit_look(asset["vertices"], t, out["vertices"], out["triangles"],
                      {c: (asset[c], out[c], c) for c in channels}, result.kept)
    for c in channels:
        out[c] = fitted[c].reshape(out[c].shape)
    return out, time.perf_counter() - start


# -- meshoptimizer -----------------------------------------------------------------------------

def meshoptimizer_module():
    """PyPI's meshoptimizer: this Python's, or from a venv made once under TOPSTOC_CACHE."""
    try:
        import meshoptimizer
        return meshoptimizer
    except ImportError:
        pass
    venv = CACHE / "venv-meshoptimizer"
    python = venv / "bin" / "python"
    try:
        if not python.exists():
            subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
            subprocess.run([str(python), "-m", "pip", "install", "-q", "meshoptimizer==0.2.30a0"], check=True)
        site = subprocess.run([str(python), "-c", "import meshoptimizer, os; print(os.path.dirname(os.path.dirname("
                               "meshoptimizer.__file__)))"], check=True, capture_output=True, text=True).stdout.strip()
    except (subprocess.CalledProcessError, OSError) as error:
        print(f"note: meshoptimizer is not available ({error})")
        return None
    sys.path.append(site)
    import meshoptimizer
    return meshoptimizer


def simplify_with_attributes(module):
    """meshopt_simplifyWithAttributes from the package's library, typed here: the package's own
    wrapper declares no argument types, so ctypes cannot pass its float and size_t arguments."""
    from meshoptimizer._loader import lib
    function = lib.meshopt_simplifyWithAttributes
    pointer = ctypes.c_void_p
    size = ctypes.c_size_t
    function.argtypes = [pointer, pointer, size, pointer, size, size, pointer, size, pointer, size, pointer,
                         size, ctypes.c_float, ctypes.c_uint, ctypes.POINTER(ctypes.c_float)]
    function.restype = size
    return function


def run_meshopt(module, asset: dict, triangles: int) -> tuple[dict, float] | None:
    """meshopt_simplifyWithAttributes to ``triangles`` on the asset split by its corner values
    (target_error 1, i.e. unbounded, as tests/peers/meshopt_simplify.cpp)."""
    t = asset["triangles"]
    channels = [c for c in CHANNELS if asset.get(c) is not None]
    corner = np.concatenate([t.reshape(-1, 1)] + [asset[c].reshape(len(t) * 3, -1) for c in channels], axis=1)
    unique, inverse = np.unique(corner, axis=0, return_inverse=True)
    positions = np.ascontiguousarray(asset["vertices"][unique[:, 0].astype(np.int64)], dtype=np.float32)
    attributes = np.ascontiguousarray(unique[:, 1:], dtype=np.float32)
    weights = np.concatenate([np.full(asset[c].shape[2], MESHOPT_WEIGHTS[c]) for c in channels]).astype(np.float32)
    indices = np.ascontiguousarray(inverse.ravel(), dtype=np.uint32)
    destination = np.zeros(len(indices), dtype=np.uint32)
    error = ctypes.c_float(0.0)
    start = time.perf_counter()
    count = simplify_with_attributes(module)(
        destination.ctypes.data, indices.ctypes.data, len(indices), positions.ctypes.data, len(positions), 12,
        attributes.ctypes.data, 4 * attributes.shape[1], weights.ctypes.data, len(weights), None,
        3 * triangles, 1.0, 0, ctypes.byref(error))
    seconds = time.perf_counter() - start
    out_t = destination[:count].reshape(-1, 3).astype(np.int64)
    out = {"vertices": positions.astype(np.float64), "triangles": out_t}
    column = 0
    for c in channels:
        width = asset[c].shape[2]
        out[c] = unique[:, 1 + column:1 + column + width][out_t]
        column += width
    return out, seconds


# -- Blender -----------------------------------------------------------------------------------

BLENDER_SCRIPT = r"""
import json, sys, time
import bpy
import numpy as np
for job in json.load(open(sys.argv[1])):
    try:
        data = np.load(job["input"])
        v, t = data["vertices"], data["triangles"]
        bpy.ops.wm.read_factory_settings(use_empty=True)
        mesh = bpy.data.meshes.new("m")
        mesh.from_pydata(v.tolist(), [], t.tolist())
        if "uv" in data:
            layer = mesh.uv_layers.new(name="UVMap")
            layer.data.foreach_set("uv", data["uv"].ravel())
        if "color" in data:
            colors = mesh.color_attributes.new("Col", "FLOAT_COLOR", "CORNER")
            rgba = np.concatenate([data["color"].reshape(-1, 3), np.ones((3 * len(t), 1))], axis=1)
            colors.data.foreach_set("color", rgba.ravel())
        mesh.shade_smooth()
        if "normal" in data:
            mesh.normals_split_custom_set(data["normal"].reshape(-1, 3).tolist())
        mesh.update()
        obj = bpy.data.objects.new("m", mesh)
        bpy.context.scene.collection.objects.link(obj)
        bpy.context.view_layer.objects.active = obj
        mod = obj.modifiers.new("d", "DECIMATE")
        mod.decimate_type = "COLLAPSE"
        mod.ratio = job["ratio"]
        mod.use_collapse_triangulate = True
        start = time.perf_counter()
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        out = evaluated.to_mesh()
        seconds = time.perf_counter() - start
        out.calc_loop_triangles()
        ov = np.empty(3 * len(out.vertices)); out.vertices.foreach_get("co", ov)
        ot = np.empty(3 * len(out.loop_triangles), dtype=np.int64); out.loop_triangles.foreach_get("vertices", ot)
        loops = np.empty(3 * len(out.loop_triangles), dtype=np.int64); out.loop_triangles.foreach_get("loops", loops)
        result = {"vertices": ov.reshape(-1, 3), "triangles": ot.reshape(-1, 3), "seconds": seconds}
        if "uv" in data:
            uv = np.empty(2 * len(out.loops)); out.uv_layers[0].data.foreach_get("uv", uv)
            result["uv"] = uv.reshape(-1, 2)[loops].reshape(-1, 3, 2)
        if "color" in data:
            rgba = np.empty(4 * len(out.loops)); out.color_attributes["Col"].data.foreach_get("color", rgba)
            result["color"] = rgba.reshape(-1, 4)[loops, :3].reshape(-1, 3, 3)
        if "normal" in data:
            normal = np.empty(3 * len(out.loops)); out.corner_normals.foreach_get("vector", normal)
            result["normal"] = normal.reshape(-1, 3)[loops].reshape(-1, 3, 3)
        np.savez(job["output"], **result)
        evaluated.to_mesh_clear()
    except Exception as error:  # the case then shows Blender as not available, named on stderr
        print(f"blender job {job['output']}: {error}", file=sys.stderr)
"""


def run_blender(jobs: list[dict], work: pathlib.Path) -> list[tuple[dict, float] | None]:
    """Blender's Collapse on each job ({"asset", "triangles"}), in one bpy process."""
    specs = []
    for k, job in enumerate(jobs):
        asset = job["asset"]
        arrays = {key: asset[key] for key in ("vertices", "triangles", *CHANNELS) if asset.get(key) is not None}
        np.savez(work / f"in{k}.npz", **arrays)
        specs.append({"input": str(work / f"in{k}.npz"), "output": str(work / f"out{k}.npz"),
                      "ratio": job["triangles"] / len(asset["triangles"])})
    (work / "jobs.json").write_text(json.dumps(specs))
    (work / "blender.py").write_text(BLENDER_SCRIPT)
    if not pathlib.Path(BPY_PYTHON).exists():
        print(f"note: no bpy Python at {BPY_PYTHON} (TOPSTOC_BPY_PYTHON): Blender is missing")
        return [None] * len(jobs)
    subprocess.run([BPY_PYTHON, str(work / "blender.py"), str(work / "jobs.json")], check=False)
    found = []
    for spec in specs:
        if not pathlib.Path(spec["output"]).exists():
            found.append(None)
            continue
        data = dict(np.load(spec["output"]))
        found.append((data, float(data.pop("seconds"))))
    return found


# -- the report --------------------------------------------------------------------------------

def figures(asset: dict, out: tuple[dict, float] | None, samples: int) -> dict | None:
    if out is None:
        return None
    result, seconds = out
    errors = attribute_errors(asset, result, closest_points, samples)
    distance = hausdorff(Mesh(asset["vertices"], asset["triangles"]),
                         Mesh(np.asarray(result["vertices"], dtype=np.float64), result["triangles"]))
    return {"triangles": int(len(result["triangles"])), "seconds": seconds, **errors,
            "geometry_mean": 100 * distance.symmetric.mean / distance.diagonal}


# Errors below these count as exact (geometry in % of the diagonal, as bench_quality.py's EXACT).
EXACT = {"geometry_mean": 1e-6}


def ratio(ours: float, peer: float, channel: str = "") -> float:
    """ours / peer, each raised to the noise floor first (EXACT, else 1e-9)."""
    floor = EXACT.get(channel, 1e-9)
    return max(ours, floor) / max(peer, floor)


def print_case(case: dict) -> None:
    tools = case["tools"]
    ours = tools["topstoc quality"]
    print(f"\n{case['asset']} at {case['ratio']:.0%} ({case['input_triangles']} triangles, "
          f"target {case['target_triangles']})")
    print(f"  {'tool':32s} {'triangles':>9s} " + " ".join(f"{c:>9s}" for c in case["channels"])
          + f" {'geom. %':>9s}   ours ÷ this")
    for name, row in tools.items():
        if row is None:
            print(f"  {name:32s} missing")
            continue
        ratios = "" if name == "topstoc quality" else " ".join(
            f"{ratio(ours[c], row[c], c):6.2f}" for c in case["channels"])
        print(f"  {name:32s} {row['triangles']:9d} " + " ".join(f"{row[c]:9.4g}" for c in case["channels"])
              + f" {row['geometry_mean']:9.3g}   {ratios}")


def summarize(cases: list[dict]) -> dict:
    """Per peer and channel: the median and worst of ours ÷ peer over the cases."""
    summary = {}
    print("\nours ÷ peer (below 1: ours is closer to the source's look)")
    for peer in PEERS:
        for channel in (*CHANNELS, "geometry_mean"):
            values = [ratio(c["tools"]["topstoc quality"][channel], c["tools"][peer][channel], channel)
                      for c in cases if channel in (*c["channels"], "geometry_mean") and c["tools"].get(peer)]
            if not values:
                continue
            entry = {"median": statistics.median(values), "worst": max(values), "cases": len(values),
                     "above_1": sum(v > 1.0 for v in values)}
            summary[f"{channel} vs {peer}"] = entry
            print(f"  {channel:13s} vs {peer:32s} median {entry['median']:.3f}  worst {entry['worst']:.3f}  "
                  f"above 1.0 in {entry['above_1']} of {entry['cases']}")
    return summary


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ratios", default="0.1,0.02")
    parser.add_argument("--samples", type=int, default=50_000, help="points per direction")
    parser.add_argument("--assets", default="", help="comma-separated names (default: all)")
    parser.add_argument("--weight", type=float, default=ATTRIBUTE_WEIGHT, help="our attribute weight")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args()
    print(f"machine: {machine()}")
    meshopt = meshoptimizer_module()
    cases, blender_jobs = [], []
    for asset in assets([a for a in args.assets.split(",") if a]):
        for r in (float(x) for x in args.ratios.split(",")):
            ours = run_ours(asset, r, args.weight)
            triangles = len(ours[0]["triangles"])
            case = {"asset": asset["name"], "ratio": r, "input_triangles": int(len(asset["triangles"])),
                    "target_triangles": target_triangles(asset, r),
                    "channels": [c for c in CHANNELS if asset.get(c) is not None],
                    "tools": {"topstoc quality": figures(asset, ours, args.samples),
                              PEERS[0]: figures(asset, meshopt and run_meshopt(meshopt, asset, triangles),
                                                args.samples)}}
            cases.append(case)
            blender_jobs.append({"asset": asset, "triangles": triangles})
    with tempfile.TemporaryDirectory(prefix="topstoc-attrs-") as work:
        for case, job, out in zip(cases, blender_jobs, run_blender(blender_jobs, pathlib.Path(work))):
            case["tools"][PEERS[1]] = figures(job["asset"], out, args.samples)
    for case in cases:
        print_case(case)
    summary = summarize(cases)
    if args.json:
        report = {"benchmark": "tests/bench/bench_attributes.py", "machine": machine(),
                  "date": time.strftime("%Y-%m-%d", time.gmtime()), "samples": args.samples,
                  "attribute_weight": args.weight, "meshopt_weights": MESHOPT_WEIGHTS,
                  "cases": cases, "summary": summary}
        path = pathlib.Path(args.json)
        temporary = path.with_suffix(".tmp")
        temporary.write_text(json.dumps(report, indent=1))
        temporary.replace(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
