"""``loops IN``: handle and tunnel loops of a mesh file (docs/design.md §6).

Prints, per component (ordered by smallest vertex id), the genus and the g handle and g tunnel
loops as vertex ids in the file's vertex order, with their lengths. A component the search refuses
(not manifold, self-intersecting) is one line, status "refused", and the others are searched;
when every component is refused that is the error. With --json the document
is ``{components: [{genus, status, handles: [[ids...]...], tunnels: [[...]...], ...}], seconds}``.
"""

from __future__ import annotations

import argparse
import time
from ..support.errors import TopStocError
from . import progress, subcommand


def add_parser(subparsers) -> None:
    parser = subcommand(
        subparsers, "loops", "handle and tunnel loops",
        "Handle and tunnel loops of every closed orientable component (TetGen + "
        "persistence, shortened on the surface). Large components go through a "
        "coarse decimation of themselves and the loops are carried back.",
        ("input", "IN", "mesh file (OBJ, PLY, OFF, STL, optionally .gz/.bz2)"))
    route = parser.add_mutually_exclusive_group()
    route.add_argument("--coarse-vertices", type=int, metavar="N",
                       help="always go through a coarse decimation with about N vertices")
    route.add_argument("--full", action="store_true",
                       help="always tetrahedralize the full components (slow on large meshes)")
    parser.add_argument("--no-shorten", action="store_true", help="return the loops as selected")
    parser.add_argument("--metric", choices=("length", "edges"), default="length",
                        help="choose and shorten loops by length (default) or edge count (the thesis)")
    parser.add_argument("--seed", type=int, default=1, metavar="S", help="decimation seed of the coarse route (default 1)")
    parser.add_argument("--json", action="store_true", help="print a JSON document")
    progress.add_arguments(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..api.io import read_mesh  # imported here so that --help works without the readers
    from ..api.component_loops import all_refused, loops_by_component, refusals
    from ..api.mesh import Mesh

    data = read_mesh(args.input)
    if args.coarse_vertices is not None and args.coarse_vertices <= 0:
        raise TopStocError(f"--coarse-vertices must be positive, got {args.coarse_vertices}")
    progress.stage("finding handle and tunnel loops")
    started = time.perf_counter()
    mesh = Mesh(data.vertices, data.triangles)
    # a refused component (not manifold, self-intersecting) is reported and the others searched
    result = loops_by_component(data.vertices, data.triangles, mesh=mesh,
                                coarse_vertices=0 if args.full else args.coarse_vertices,
                                shorten=not args.no_shorten, metric=args.metric, seed=args.seed)
    if all_refused(result):
        raise TopStocError("; ".join(refusals(result)))
    seconds = time.perf_counter() - started
    document = result.as_json()
    document["seconds"] = {"total": seconds, **document["seconds"]}
    document["input"] = {"path": args.input, "vertices": len(data.vertices), "triangles": len(data.triangles)}
    if args.json:
        from . import print_json

        print_json(document)
        return 0
    print(f"{args.input}: {len(data.vertices)} vertices, {len(data.triangles)} triangles, "
          f"{len(result.components)} component{'s' if len(result.components) != 1 else ''}, {seconds:.2f} s")
    for index, component in enumerate(result.components):
        if component.status != "ok":
            print(f"component {index} (from vertex {component.first_vertex}): {component.status}: {component.detail}")
            continue
        print(f"component {index} (from vertex {component.first_vertex}): genus {component.genus}"
              + (f", {component.route} route ({component.analysed_vertices} vertices tetrahedralized)"
                 if component.route else ""))
        for loop in component.loops:
            print(f"  {loop.kind} {len(loop.vertices)} edges, length {loop.length:.6g} "
                  f"(before shortening {loop.initial_length:.6g}): {' '.join(map(str, loop.vertices.tolist()))}")
    return 0
