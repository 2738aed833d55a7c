"""Batch decimation inside Blender: mesh files and .blend files (SPEC section 6).

Mesh files (OBJ, PLY, OFF, STL, optionally .gz/.bz2) go through topstoc.core.io in the file's
own vertex order and are written in the same format, with UVs, vertex colours and materials
carried over; UV seams and material borders are kept. A .blend file is opened, its mesh
objects (all, or those named with --objects) are decimated in place with the guidance stored
on them, and the file is saved under the output folder. One progress line per input, a JSON
report, and exit code 1 when any input failed (the others are still processed).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import traceback


from ..core.mesh import Mesh

BLEND = ".blend"


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="blender -b --python topstoc/batch.py --",
        description="Decimate meshes and .blend files with TopStoc.")
    parser.add_argument("--input", nargs="+", required=True, metavar="FILE",
                        help="mesh files (.obj .ply .off .stl, optionally .gz/.bz2) or .blend files")
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument("--ratio", type=float, help="fraction of the vertices to keep, in (0, 1]")
    target.add_argument("--vertices", type=int, help="output vertex count")
    target.add_argument("--triangles", type=int, help="output triangle count")
    target.add_argument("--max-error", metavar="E[%]",
                        help="largest Hausdorff deviation, absolute or in %% of the bounding-box diagonal")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--adaptivity", type=float, default=0.5)
    parser.add_argument("--density", choices=("off", "uniform", "adaptive"), default="off")
    parser.add_argument("--mode", choices=("quality", "fast"), default="quality",
                        help="quality (default): TopStoc then quadric edge collapses; fast: plain TopStoc")
    parser.add_argument("--placement", choices=("subsample", "filtered"), default=None,
                        help="default: set by --mode")
    parser.add_argument("--refine", type=float, default=None, metavar="F",
                        help="0: off; F: TopStoc to F x the target, then quadric collapses (default: set by --mode)")
    parser.add_argument("--objects", nargs="+", metavar="NAME", help="objects to decimate in .blend inputs "
                                                                      "(default: every mesh object)")
    parser.add_argument("--output", required=True, metavar="DIR")
    parser.add_argument("--json", metavar="REPORT.json", help="write the report here")
    return parser.parse_args(argv)


def _target(args, diagonal: float) -> dict:
    if args.ratio is not None:
        return {"ratio": args.ratio}
    if args.vertices is not None:
        return {"vertices": args.vertices}
    if args.triangles is not None:
        return {"triangles": args.triangles}
    from ..core.decimate import decimate as decimate_function
    import inspect

    if "max_error" not in inspect.signature(decimate_function).parameters:
        raise ValueError("--max-error needs the Hausdorff engine, which this build lacks")
    text = args.max_error.strip()
    try:
        if text.endswith("%"):
            return {"max_error": float(text[:-1]) / 100.0, "relative": True}
        return {"max_error": float(text)}
    except ValueError:
        raise ValueError(f"--max-error must be a number or a percentage, got '{args.max_error}'") from None


def _options(args) -> dict:
    return dict(seed=args.seed, adaptivity=args.adaptivity, density=args.density, mode=args.mode,
                placement=args.placement, refine=args.refine)


def decimate_mesh_file(path: str, out_dir: str, args) -> dict:
    """Decimates one mesh file; returns its report entry."""
    from ..core import attributes, io

    data = io.read_mesh(path)
    if data.num_triangles == 0:
        raise ValueError(f"{path}: no faces to decimate")
    start = time.perf_counter()
    mesh = Mesh(data.vertices, data.triangles)
    borders = None
    if data.corner_uvs is not None:
        seams = attributes.uv_seam_edges(data.triangles, data.corner_uvs)
        borders = seams if len(seams) else None
    result = mesh.decimate(**_target(args, mesh.diagonal), **_options(args), borders=borders,
                           regions=attributes.material_regions(data))
    seconds = time.perf_counter() - start
    out = attributes.transfer_attributes(data, result)
    target = os.path.join(out_dir, os.path.basename(path))
    io.write_mesh(target, out)
    return {"input": path, "output": target, "vertices_in": data.num_vertices,
            "vertices_out": result.num_vertices, "triangles_out": result.num_triangles,
            "seconds": seconds, "repairs": result.stats.repairs, "error": _achieved_error(result)}


def _achieved_error(result):
    """The measured symmetric Hausdorff error for --max-error runs, else None."""
    bound = getattr(result, "error_bound", None)
    return None if bound is None else float(bound.achieved_error)


class _Params:
    """DecimationParameters for the pipeline from the command line."""

    def __init__(self, args, target: dict):
        self.target_mode = {"ratio": "RATIO", "vertices": "VERTICES", "triangles": "TRIANGLES",
                            "max_error": "MAX_ERROR"}[next(iter(target))]
        self.ratio = args.ratio or 0.1
        self.vertices = args.vertices or 1
        self.triangles = args.triangles or 1
        self.max_error = target.get("max_error", 0.0) * (100.0 if target.get("relative") else 1.0)
        self.max_error_relative = bool(target.get("relative"))
        self.seed, self.adaptivity, self.density = args.seed, args.adaptivity, args.density
        self.quality_mode = args.mode.upper()
        self.placement, self.refine = args.placement, args.refine


def decimate_blend_file(path: str, out_dir: str, args) -> dict:
    """Decimates the mesh objects of a .blend file in place and saves a copy in ``out_dir``."""
    import bpy

    from . import pipeline

    if not os.path.isfile(path):
        raise FileNotFoundError(f"{path}: no such file")
    bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    objects = [o for o in bpy.data.objects if o.type == "MESH"]
    if args.objects:
        missing = [name for name in args.objects if bpy.data.objects.get(name) is None]
        if missing:
            raise ValueError(f"{path}: no object named {', '.join(repr(m) for m in missing)}")
        objects = [bpy.data.objects[name] for name in args.objects]
        wrong = [o.name for o in objects if o.type != "MESH"]
        if wrong:
            raise ValueError(f"{path}: {', '.join(wrong)} is not a mesh object")
    if not objects:
        raise ValueError(f"{path}: no mesh objects")
    entries, seconds = [], 0.0
    vertices_in = vertices_out = triangles_out = 0
    done = set()
    for obj in objects:
        if obj.data.name in done:  # a mesh shared by several objects is decimated once
            continue
        done.add(obj.data.name)
        n = len(obj.data.vertices)
        prepared = pipeline.prepare(obj)
        params = _Params(args, _target(args, prepared.mesh.diagonal))
        run = pipeline.decimate(bpy.context, obj, params)
        pipeline.write_output(run, "IN_PLACE")
        seconds += run.seconds
        vertices_in += n
        vertices_out += run.result.num_vertices
        triangles_out += run.result.num_triangles
        entries.append({"object": obj.name, "vertices_in": n, "vertices_out": run.result.num_vertices,
                        "triangles_out": run.result.num_triangles, "seconds": run.seconds,
                        "repairs": run.result.stats.repairs, "error": _achieved_error(run.result)})
    target = os.path.join(out_dir, os.path.basename(path))
    bpy.context.preferences.filepaths.save_version = 0  # no .blend1 backups next to the outputs
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(target), copy=True)
    return {"input": path, "output": target, "vertices_in": vertices_in, "vertices_out": vertices_out,
            "triangles_out": triangles_out, "seconds": seconds, "error": None, "objects": entries}


def _register_addon() -> None:
    """The .blend path reads guidance settings stored on objects: register the add-on's types."""
    import bpy

    from .. import register

    if not hasattr(bpy.types.Object, "topstoc"):
        register()


def main(argv=None) -> int:
    if argv is None:
        argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        args = parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    os.makedirs(args.output, exist_ok=True)
    report = {"results": [], "failures": []}
    total = len(args.input)
    for i, path in enumerate(args.input, 1):
        prefix = f"topstoc batch [{i}/{total}] {path}"
        print(f"{prefix}: decimating ...", flush=True)
        try:
            if path.lower().endswith(BLEND):
                _register_addon()
                entry = decimate_blend_file(path, args.output, args)
            else:
                entry = decimate_mesh_file(path, args.output, args)
        except Exception as error:  # one broken input must not stop the batch
            message = str(error).splitlines()[0] if str(error) else type(error).__name__
            message = message[len("Error: "):] if message.startswith("Error: ") else message  # bpy.ops
            if not isinstance(error, (ValueError, OSError, RuntimeError)):
                traceback.print_exc()
            report["failures"].append({"input": path, "message": message})
            print(f"{prefix}: FAILED: {message}", file=sys.stderr, flush=True)
            continue
        report["results"].append(entry)
        print(f"{prefix}: {entry['vertices_in']} -> {entry['vertices_out']} vertices, "
              f"{entry['triangles_out']} triangles in {entry['seconds']:.3f} s -> {entry['output']}", flush=True)
    if args.json:
        with open(args.json, "w") as stream:
            json.dump(report, stream, indent=2)
    print(f"topstoc batch: {len(report['results'])} done, {len(report['failures'])} failed", flush=True)
    return 1 if report["failures"] else 0
