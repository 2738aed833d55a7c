"""``python3 -m topstoc decimate IN OUT``: TopStoc decimation of a mesh file (docs/design.md §6).

The output keeps the input's UVs, vertex colours and materials: material borders and UV
seams are passed to the decimation as borders, so they survive, and the attributes are
copied through the result's corner and face source maps. In quality mode the UVs and colours
also enter the collapse cost (``--attribute-weight``, topstoc.core.carry.appearance), so a UV-mapped
asset keeps its look. ``seconds`` in the JSON report is
the work itself (mesh preparation, seams, decimation), without reading and writing files.
"""

from __future__ import annotations

import time

import numpy as np

from ..carry.appearance import attribute_weight, refines
from ..batch.settings import parse_max_error
from ..api.budget import missed_dict, missed_text
from ..support.errors import TopStocError
from ..api.io import mesh_format, read_mesh
from ..api.job import ATTRIBUTE_WEIGHT, MODES
from ..api.mesh_file_job import prepare_file
from ..support.output_guard import add_overwrite_argument, prepare_output
from ..api.symmetry import AXES
from . import messages, print_json, progress, subcommand

DENSITIES = ("off", "uniform", "adaptive")


def add_parser(subparsers) -> None:
    parser = subcommand(
        subparsers, "decimate", "decimate a mesh file with TopStoc",
        "Decimate IN to OUT (OBJ, PLY, OFF, STL, optionally .gz) with topology control. "
        "UVs, vertex colours and materials are kept. Give exactly one target.",
        ("input", "IN", "input mesh file"),
        ("output", "OUT", "output mesh file (format from its extension)"))
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument("--ratio", type=float, metavar="R", help="fraction of the vertices to keep, in (0, 1]")
    target.add_argument("--vertices", type=int, metavar="N", help="output vertex count")
    target.add_argument("--triangles", type=int, metavar="N", help="output triangle count")
    target.add_argument("--max-error", metavar="E[%]",
                        help="largest Hausdorff deviation, absolute or in %% of the bounding-box diagonal")
    parser.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default 0)")
    parser.add_argument("--adaptivity", type=float, default=0.5, metavar="A",
                        help="0 samples uniformly, 1 follows curvature fully (default 0.5)")
    parser.add_argument("--density", choices=DENSITIES, default="off",
                        help="Poisson-disk density control of the samples (default off)")
    parser.add_argument("--mode", choices=MODES, default="quality",
                        help="quality (default): TopStoc to a few times the target, then quadric edge "
                             "collapses; best: quality, then large results fitted to the input too (lower "
                             "mean deviation, about 1.5x the time); fast: the thesis' plain TopStoc "
                             "(milliseconds, higher deviation)")
    parser.add_argument("--placement", choices=("subsample", "filtered"), default=None,
                        help="keep input positions, or move surface vertices to their cluster's "
                             "quadric-optimal point (default: filtered in quality mode, subsample in fast)")
    parser.add_argument("--refine", type=float, default=None, metavar="F",
                        help="0: off. F >= 1: TopStoc keeps F x the target, then edge collapses by quadric "
                             "error (default: set by --mode)")
    parser.add_argument("--attribute-weight", type=float, default=ATTRIBUTE_WEIGHT, metavar="W",
                        help="how much the input's UVs and vertex colours count in quality mode's collapses: "
                             "a difference d costs as much as moving the surface by W x d bounding-box "
                             f"diagonals (default {ATTRIBUTE_WEIGHT}; 0 = geometry only; fast mode ignores it)")
    parser.add_argument("--symmetry", type=str.upper, choices=AXES, metavar="{x,y,z}",
                        help="mirror-symmetric result across the plane through the origin normal to this "
                             "axis (like Blender's Decimate modifier; the input must be symmetric there)")
    parser.add_argument("--guidance", metavar="FILE.npy",
                        help="per-vertex guidance u in [-1, 1] in the input file's vertex order "
                             "(STL: welded order); 1 keeps a vertex, -1 avoids it")
    parser.add_argument("--json", action="store_true", help="print a JSON report")
    add_overwrite_argument(parser)
    progress.add_arguments(parser)
    parser.set_defaults(run=run)


def load_guidance(path: str, num_vertices: int) -> np.ndarray:
    """A (num_vertices,) float array from a .npy file; ValueError naming the file otherwise."""
    try:
        u = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise
    except (OSError, ValueError) as error:
        raise TopStocError(f"{path}: not a readable .npy file ({error})") from None
    if u.dtype.kind not in "fiub":
        raise TopStocError(f"{path}: guidance must be numbers, got dtype {u.dtype}")
    if u.shape != (num_vertices,):
        raise TopStocError(f"{path}: guidance must hold one value per input vertex ({num_vertices}), "
                           f"got shape {u.shape}")
    u = u.astype(np.float64)
    bad = np.flatnonzero(~(np.abs(u) <= 1))  # also catches NaN
    if len(bad):
        raise TopStocError(f"{path}: guidance of vertex {bad[0]} is {u[bad[0]]}; values must lie in [-1, 1]")
    return u


def _error_bound_report(result) -> dict:
    """How an error-bounded search went (absolute errors), when --max-error was used."""
    report = getattr(result, "error_bound", None)
    if report is None:
        return {}
    return {"error_bound": {"max_error": report.max_error, "achieved_error": report.achieved_error,
                            "target_vertices": report.target_vertices, "failed_target": report.failed_target,
                            "probes": len(report.probes), "seconds": report.seconds}}


def attribute_report(requested: float, used: bool, args, data, appearance) -> dict:
    """The attribute weight the decimation used, and why it is 0 when it is."""
    report = {"weight": requested if used else 0.0, "requested_weight": requested,
              "channels": appearance.channels, "uv_corners_filled": appearance.uv_corners_filled}
    if not used:
        if requested == 0:
            report["unused_because"] = "--attribute-weight 0"
        elif not refines(args.mode, args.refine):
            report["unused_because"] = f"{args.mode} mode (only the quality refinement weighs attributes)"
        elif data.corner_uvs is None and data.vertex_colors is None:
            report["unused_because"] = "the input has no UVs or vertex colours"
        else:
            report["unused_because"] = "the input's UVs and colours leave no channel to weigh"
    return report


def _target(args) -> dict:
    """The decimation target of the arguments: ratio, a count, or an error bound."""
    if args.max_error is not None:
        bound, relative = parse_max_error(args.max_error)
        return {"max_error": bound, "relative": relative}
    return {"ratio": args.ratio, "target_vertices": args.vertices, "target_triangles": args.triangles}


def run(args) -> int:
    prepare_output(args.output, [args.input, args.guidance], overwrite=args.overwrite)
    mesh_format(args.output)  # fail on a bad output name before doing any work
    progress.stage(f"reading {args.input}")
    data = read_mesh(args.input)
    guidance = None if args.guidance is None else load_guidance(args.guidance, data.num_vertices)
    weight = attribute_weight(args.attribute_weight)
    target = _target(args)

    start = time.perf_counter()
    source = prepare_file(args.input, data, args.mode, args.refine, weight)
    options = dict(seed=args.seed, adaptivity=args.adaptivity, density=args.density, guidance=guidance,
                   mode=args.mode, placement=args.placement, refine=args.refine)
    searching = f"searching the vertex count for --max-error {args.max_error}"
    progress.stage("decimating" if args.max_error is None else searching)

    def probed(probe, count, vertices, error, passed):  # one stage line per probe of the search
        progress.stage(f"{searching}: probe {probe}, {vertices:,} vertices, error {error:.4g} "
                       f"{'within' if passed else 'above'} the bound")

    result = source.decimate(target, options, args.symmetry, probed if args.max_error is not None else None)
    seconds = time.perf_counter() - start
    progress.stage(f"writing {args.output}")
    dropped = source.write(result, args.output)

    stats, seams, appearance = result.stats, source.seams, source.appearance
    if args.json:
        report = source.mesh.report()
        print_json({
            "input": {"path": args.input, "vertices": data.num_vertices, "triangles": data.num_triangles,
                      "uvs": data.corner_uvs is not None, "vertex_colors": data.vertex_colors is not None,
                      "materials": len(data.material_names), "uv_seam_edges": 0 if seams is None else len(seams),
                      "dropped_triangles": report.degenerate_triangles + report.duplicate_triangles,
                      "components": report.components, "manifold": report.manifold, "closed": report.closed},
            "output": {"path": args.output, "vertices": result.num_vertices, "triangles": result.num_triangles,
                       "dropped_attributes": dropped},
            "target": {key: value for key, value in (("ratio", args.ratio), ("vertices", args.vertices),
                                                    ("triangles", args.triangles), ("max_error", args.max_error))
                       if value is not None},
            "target_missed": missed_dict(stats),
            "seed": args.seed,
            "symmetry": args.symmetry,
            "seconds": seconds,
            "seconds_by_stage": {"prepare": seconds - sum(stats.seconds.values()), **stats.seconds},
            "repairs": stats.repairs,
            "repair_rounds": stats.repair_rounds,
            "topology_kept": stats.topology_kept,
            "issues_remaining": stats.issues_remaining,
            "guided": stats.guided,
            "samples_selected": stats.selected,
            "density_rejected": stats.density_rejected,
            "refine": {"mode": args.mode, "factor": result.parameters["refine"],
                       "placement": result.parameters["placement"], "vertices": stats.refine_vertices,
                       "collapses": stats.refine_collapses},
            "attributes": attribute_report(weight, bool(source.attribute_kwargs), args, data, appearance),
            "aspect_ratio": result.aspect_ratio(),
            **_error_bound_report(result),
        })
    else:
        print(f"{args.input}: {data.num_vertices} vertices, {data.num_triangles} triangles -> {args.output}: "
              f"{result.num_vertices} vertices, {result.num_triangles} triangles in {seconds:.3f} s "
              f"({stats.repairs} repair samples)" + missed_text(stats)
              + (f"; not written: {', '.join(dropped)}" if dropped else ""))
    if stats.topology_warning:  # exit 0 (the output is written), but never silently
        messages.print_warning(f"{args.output}: {stats.topology_warning}")
    return 0
