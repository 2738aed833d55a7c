"""``python3 -m topstoc topology IN``: topological invariants of a mesh file (docs/design.md §6).

Prints per connected component V, E, F, Euler characteristic, Betti numbers over Z2, whether
it is closed, orientable and manifold, its genus (or cross-caps) and boundary loops. With
``--generators`` also the 2g generator edges and a loop through each, for every closed
orientable manifold component. Vertex ids are the file's (STL: welded by exact position).
``seconds`` is the analysis itself, without reading the file.
"""

from __future__ import annotations

import time

from ..api.io import read_mesh
from ..api.topology import topology
from . import print_json, progress, subcommand

#: Components listed in the text report before "... and N more".
TEXT_COMPONENTS = 20


def add_parser(subparsers) -> None:
    parser = subcommand(
        subparsers, "topology", "topological invariants per component",
        "Betti numbers, Euler characteristic, genus, orientability, manifoldness and "
        "boundary loops of every connected component of IN (OBJ, PLY, OFF, STL, .gz).",
        ("input", "IN", "input mesh file"))
    parser.add_argument("--generators", action="store_true",
                        help="also the 2g generator edges and loops of each closed orientable component")
    parser.add_argument("--json", action="store_true", help="print a JSON report")
    progress.add_arguments(parser)
    parser.set_defaults(run=run)


def run(args) -> int:
    data = read_mesh(args.input)
    progress.stage("analysing the topology")
    start = time.perf_counter()
    info = topology(data.vertices, data.triangles, generators=args.generators)
    seconds = time.perf_counter() - start
    if args.json:
        report = {"input": args.input, "seconds": seconds}
        report.update(info.to_dict())
        print_json(report)
        return 0
    b0, b1, b2 = info.betti
    print(f"{args.input}: {info.vertices} vertices, {info.edges} edges, {info.faces} faces, "
          f"euler {info.euler}, betti {b0}/{b1}/{b2}")
    if info.duplicate_triangles or info.collapsed_triangles:
        print(f"  {info.duplicate_triangles} duplicate triangles counted once, "
              f"{info.collapsed_triangles} triangles with a repeated vertex read as edges")
    for c in info.components[:TEXT_COMPONENTS]:
        print(f"  component {c.index}: {c.summary} ({c.vertices} V, {c.edges} E, {c.faces} F, euler {c.euler})")
    if len(info.components) > TEXT_COMPONENTS:
        print(f"  ... and {len(info.components) - TEXT_COMPONENTS} more components (--json lists all)")
    if len(info.isolated_vertices):
        print(f"  {len(info.isolated_vertices)} isolated vertices (in no edge or triangle; not counted in the Betti numbers)")
    for g in info.generators:
        lengths = ", ".join(str(len(loop)) for loop in g.loops)
        print(f"  component {g.component}: {len(g.edges)} generator edges" + (f", loop lengths {lengths}" if lengths else ""))
    print(f"  {seconds:.3f} s")
    return 0
