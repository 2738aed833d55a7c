"""``measure A B``: Hausdorff distance between two mesh files (docs/design.md §6).

A is the original (the input), B its approximation (the output). Prints forward (A to B: how far
the input's surface lies from the output's, i.e. what B misses of A), backward (B to A: how far the
output's surface lies from the input's, i.e. where B strays from A) and symmetric (the larger of
the two: the Hausdorff distance), each max, mean, RMS and a percentile, in % of A's bounding-box
diagonal like the rest of TopStoc (``--absolute``: in the mesh's units). ``--json`` keeps the
document's numbers absolute (``units`` says so) and adds the same figures in percent.
"""

from __future__ import annotations

import argparse
import time

from ..support import atomic
from . import progress, subcommand

from ..api.hausdorff import DEFAULT_SAMPLES, hausdorff
from ..support.output_guard import prepare_output


def add_parser(subparsers) -> None:
    parser = subcommand(
        subparsers, "measure", "Hausdorff distance between two meshes",
        "Hausdorff distance between A (the original) and B (its approximation), "
        "sampled on vertices, edges and faces (Metro / MESH style), in % of A's bounding-box "
        "diagonal. Forward (A -> B): how far A's surface lies from B's (detail B misses); "
        "backward (B -> A): how far B's surface lies from A's (where B strays); symmetric: "
        "the larger of the two, the Hausdorff distance.",
        ("a", "A", "original mesh (OBJ, PLY, OFF, STL, optionally .gz)"),
        ("b", "B", "approximation to compare with A"))
    density = parser.add_mutually_exclusive_group()
    density.add_argument("--samples", type=int, default=None,
                         metavar="N", help=f"about how many samples to take on A (default {DEFAULT_SAMPLES}); "
                              "B is sampled with the same spacing")
    density.add_argument("--step", type=float, default=None, metavar="D",
                         help="sample spacing in the meshes' units (instead of --samples)")
    parser.add_argument("--percentile", type=float, default=95.0, metavar="P",
                        help="rank in percent of the k-th ranked distance (default 95; 0 skips it)")
    units = parser.add_mutually_exclusive_group()
    units.add_argument("--absolute", action="store_true",
                       help="distances in the meshes' own units instead of %% of A's diagonal")
    units.add_argument("--relative", action="store_true",
                       help="distances as fractions of A's diagonal (0.01 = 1 %%), also in --json")
    parser.add_argument("--errors", metavar="FILE.npz",
                        help="also save per-vertex errors of A and per-face errors of B (numpy .npz)")
    parser.add_argument("--json", action="store_true", help="print a JSON document")
    progress.add_arguments(parser)
    parser.set_defaults(run=run)


def errors_file(name: str) -> str:
    """The --errors file: numpy's own rule, ".npz" appended unless the name ends with it."""
    return name if name.endswith(".npz") else name + ".npz"


def run(args: argparse.Namespace) -> int:
    from ..api.io import read_mesh  # imported here so that --help works without the readers

    errors = None if args.errors is None else errors_file(args.errors)
    prepare_output(errors, [args.a, args.b])
    progress.stage(f"reading {args.a}")
    a = read_mesh(args.a)
    progress.stage(f"reading {args.b}")
    b = read_mesh(args.b)
    progress.stage("measuring")
    started = time.perf_counter()
    result = hausdorff(a, b, samples=args.samples, step=args.step, percentile=args.percentile,
                       relative=args.relative)
    seconds = time.perf_counter() - started
    if errors is not None:
        import numpy as np

        atomic.write_file(errors, lambda stream: np.savez_compressed(
            stream, vertex_error=result.vertex_error, face_error=result.face_error))
    document = result.as_dict()
    document["units"] = "fraction of the diagonal" if args.relative else "absolute"
    document["percent_of_diagonal"] = _percent(result)
    document["seconds"] = seconds
    document["a"] = {"path": args.a, "vertices": len(a.vertices), "triangles": len(a.triangles)}
    document["b"] = {"path": args.b, "vertices": len(b.vertices), "triangles": len(b.triangles)}
    if args.json:
        from . import print_json

        print_json(document)
        return 0
    _print_table(args, a, b, result, seconds)
    return 0


def _percent(result) -> dict:
    """forward / backward / symmetric max, mean, rms, percentile in % of A's diagonal."""
    factor = 100.0 if result.relative else (100.0 / result.diagonal if result.diagonal > 0 else float("nan"))
    return {name: {key: getattr(getattr(result, name), key) * factor for key in ("max", "mean", "rms", "percentile")}
            for name in ("forward", "backward", "symmetric")}


def _print_table(args, a, b, result, seconds: float) -> None:
    if args.absolute:
        unit, figures = "", {n: {k: getattr(getattr(result, n), k) for k in ("max", "mean", "rms", "percentile")}
                             for n in ("forward", "backward", "symmetric")}
        heading = "distances in the meshes' units"
    elif args.relative:
        unit, figures = "", {n: {k: v / 100.0 for k, v in d.items()} for n, d in _percent(result).items()}
        heading = "distances as fractions of A's bounding-box diagonal"
    else:
        unit, figures = " %", _percent(result)
        heading = "distances in % of A's bounding-box diagonal"
    print(f"A (original):      {args.a} ({len(a.vertices)} vertices, {len(a.triangles)} triangles)")
    print(f"B (approximation): {args.b} ({len(b.vertices)} vertices, {len(b.triangles)} triangles)")
    print(f"{heading}; diagonal of A {result.diagonal:.6g}; step {result.step:.4g}; "
          f"samples {result.forward.samples} on A, {result.backward.samples} on B; {seconds:.3f} s")
    width = 12 + len(unit)
    print(f"{'':10s}" + "".join(f"{h:>{width}s}" for h in ("max", "mean", "rms", f"p{result.percentile_rank:g}")))
    for name in ("forward", "backward", "symmetric"):
        print(f"{name:10s}" + "".join(f"{figures[name][k]:12.4g}{unit}" for k in ("max", "mean", "rms", "percentile")))
    print("forward:   A -> B, how far A's surface lies from B's (what B misses of A; sampled on A)")
    print("backward:  B -> A, how far B's surface lies from A's (where B strays from A; sampled on B)")
    print("symmetric: the larger of the two (the Hausdorff distance)")
