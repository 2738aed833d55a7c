"""``fill-holes IN OUT`` and ``remove-handle IN OUT --index K`` (docs/design.md §6).

Both write the edited mesh (same attributes as the input: UVs, vertex colours and materials
carry over; patches take them from the hole's border) and print the new mesh's topology, with
``--json`` the same document as the ``topology`` subcommand plus an ``edit`` object saying what
was done. ``seconds`` is the work itself (loops and edit), without reading or writing files.
"""

from __future__ import annotations

import time

import numpy as np

from . import print_json, progress, subcommand
from ..support.errors import TopStocError
from ..support.output_guard import add_overwrite_argument, prepare_output


def add_parser(subparsers) -> None:
    fill = subcommand(
        subparsers, "fill-holes", "fill holes (boundary loops)",
        "Fill every hole of IN (or the ones chosen) and write OUT. Each hole is triangulated on its "
        "best-fit plane when its border projects there without overlap, else in 3D (minimum-weight "
        "triangulation). Holes are numbered over the whole mesh in the order of their lowest vertex id; "
        "the --json report lists each filled one with its first (lowest) vertex.",
        ("input", "IN", "input mesh file"),
        ("output", "OUT", "output mesh file"))
    fill.add_argument("--holes", metavar="I,J,...", help="fill only these holes (indices, comma-separated)")
    fill.add_argument("--max-edges", type=int, metavar="N", help="fill only holes with at most N edges")
    fill.add_argument("--skip-unfillable", action="store_true",
                      help="leave holes touching a non-manifold vertex or bordering a lone triangle open "
                           "instead of failing")
    fill.add_argument("--no-weld", action="store_true",
                      help="do not weld a hole's duplicate vertices (same position) into separate lobes")
    _patch_options(fill)
    fill.set_defaults(run=run_fill)

    handle = subcommand(
        subparsers, "remove-handle", "remove a handle or tunnel (cut along its loop, fill both holes)",
        "Cut IN along a handle loop (or tunnel loop) and fill both holes: the genus of that component "
        "drops by one, nothing else changes. Loops are those of the loops subcommand, counted over all "
        "components in order; or give the loop's vertex ids with --loop.",
        ("input", "IN", "input mesh file"),
        ("output", "OUT", "output mesh file"))
    which = handle.add_mutually_exclusive_group(required=True)
    which.add_argument("--index", type=int, metavar="K", help="the K-th handle loop (0-based)")
    which.add_argument("--loop", metavar="V0,V1,...", help="a closed edge loop given by its vertex ids in order")
    handle.add_argument("--tunnel", action="store_true", help="with --index: count tunnel loops instead")
    handle.add_argument("--allow-separating", action="store_true",
                        help="accept a loop that splits its component (it goes around no handle)")
    _patch_options(handle)
    handle.set_defaults(run=run_remove_handle)


def _patch_options(parser) -> None:
    parser.add_argument("--fair", action="store_true",
                        help="refine the patches to the surrounding density and fair them (adds vertices)")
    parser.add_argument("--json", action="store_true", help="print a JSON report")
    add_overwrite_argument(parser)
    progress.add_arguments(parser)


def _ids(text: str, what: str) -> list:
    try:
        values = [int(x) for x in text.replace(" ", "").split(",") if x != ""]
    except ValueError:
        raise TopStocError(f"{what} must be comma-separated integers, got {text!r}") from None
    if not values:
        raise TopStocError(f"{what} is empty")
    return values


def run_fill(args) -> int:
    prepare_output(args.output, [args.input], overwrite=args.overwrite)
    from ..api.edit import fill_holes
    from ..api.io import read_mesh

    data = read_mesh(args.input)
    holes = _ids(args.holes, "--holes") if args.holes is not None else None
    if args.max_edges is not None and args.max_edges < 3:
        raise TopStocError(f"--max-edges must be at least 3, got {args.max_edges}")
    progress.stage("filling holes")
    start = time.perf_counter()
    result = fill_holes(data.vertices, data.triangles, holes=holes, max_edges=args.max_edges,
                        skip_unfillable=args.skip_unfillable, weld_pinches=not args.no_weld, fair=args.fair)
    seconds = time.perf_counter() - start
    methods = {}
    for patch in result.patches:
        methods[patch.method] = methods.get(patch.method, 0) + 1
    filled = [{"hole": p.hole, "first_vertex": int(result.vertex_source[p.boundary].min()),
               "edges": int(len(p.boundary)), "method": p.method} for p in result.patches]
    details = {"operation": "fill-holes", "holes_filled": len({p.hole for p in result.patches}),
               "filled": filled,
               "patches": len(result.patches), "methods": methods,
               "triangles_added": int(result.num_triangles - len(data.triangles)),
               "vertices_added": int(np.count_nonzero(result.vertex_source < 0)),
               "vertices_welded": int(len(data.vertices) - np.count_nonzero(result.vertex_source >= 0))}
    return _finish(args, data, result, seconds, details)


def run_remove_handle(args) -> int:
    prepare_output(args.output, [args.input], overwrite=args.overwrite)
    from ..api.edit import remove_handle
    from ..api.io import read_mesh

    data = read_mesh(args.input)
    progress.stage("removing the handle")
    start = time.perf_counter()
    loops_seconds = 0.0
    if args.loop is not None:
        if args.tunnel:
            raise TopStocError("--tunnel goes with --index, not --loop")
        loop = np.asarray(_ids(args.loop, "--loop"))
        kind = "given"
    else:
        from ..api.loops import handle_tunnel_loops

        found = handle_tunnel_loops(data.vertices, data.triangles)
        loops_seconds = time.perf_counter() - start
        kind = "tunnel" if args.tunnel else "handle"
        candidates = found.tunnels if args.tunnel else found.handles
        if not 0 <= args.index < len(candidates):
            raise TopStocError(f"--index {args.index} is out of range: the mesh has {len(candidates)} {kind} loops")
        loop = np.asarray(candidates[args.index].vertices)
    result = remove_handle(data.vertices, data.triangles, loop, allow_separating=args.allow_separating,
                           fair=args.fair)
    seconds = time.perf_counter() - start
    details = {"operation": "remove-handle", "loop_kind": kind, "loop": loop.tolist(),
               "loops_seconds": loops_seconds, "methods": [p.method for p in result.patches],
               "triangles_added": int(result.num_triangles - len(data.triangles)),
               "vertices_added": int(result.num_vertices - len(data.vertices))}
    return _finish(args, data, result, seconds, details)


def _finish(args, data, result, seconds: float, details: dict) -> int:
    from ..api.io import write_mesh
    from ..carry.edited_mesh import carried_over
    from ..api.topology import topology

    write_mesh(args.output, carried_over(data, result))
    info = topology(result.vertices, result.triangles)
    if args.json:
        report = {"input": args.input, "output": args.output, "seconds": seconds}
        report.update(info.to_dict())
        report["edit"] = details
        print_json(report)
        return 0
    added = details["triangles_added"]
    print(f"{args.output}: {result.num_vertices} vertices, {result.num_triangles} triangles "
          f"({added:+d}), {info.summary()}")
    if details["operation"] == "fill-holes":
        methods = ", ".join(f"{count} {name}" for name, count in sorted(details["methods"].items()))
        print(f"  {details['holes_filled']} holes filled with {details['patches']} patches ({methods or 'none'})")
    else:
        print(f"  cut along a {len(details['loop'])}-vertex {details['loop_kind']} loop, "
              f"filled with {' and '.join(details['methods'])} patches")
    print(f"  {seconds:.3f} s")
    return 0
