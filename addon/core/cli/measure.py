"""``measure A B``: Hausdorff distance between two mesh files (docs/design.md §6).

A is the original, B its approximation. Prints forward (A to B), backward (B to A) and
symmetric figures, each max, mean, RMS and a percentile, and the bounding-box diagonal of A.
"""

from __future__ import annotations

import argparse
import time

from .. import atomic
from ..hausdorff import DEFAULT_SAMPLES, hausdorff
from ..output_guard import prepare_output


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "measure", help="Hausdorff distance between two meshes",
        description="Hausdorff distance between A (the original) and B (its approximation), "
                    "sampled on vertices, edges and faces (Metro / MESH style).")
    parser.add_argument("a", metavar="A", help="original mesh (OBJ, PLY, OFF, STL, optionally .gz)")
    parser.add_argument("b", metavar="B", help="approximation to compare with A")
    density = parser.add_mutually_exclusive_group()
    density.add_argument("--samples", type=int, default=None,
                         help=f"about how many samples to take on A (default {DEFAULT_SAMPLES}); "
                              "B is sampled with the same spacing")
    density.add_argument("--step", type=float, default=None, help="sample spacing (overrides --samples)")
    parser.add_argument("--percentile", type=float, default=95.0,
                        help="rank in percent of the k-th ranked distance (default 95; 0 skips it)")
    parser.add_argument("--relative", action="store_true",
                        help="print distances as fractions of A's bounding-box diagonal")
    parser.add_argument("--errors", metavar="FILE.npz",
                        help="also save per-vertex errors of A and per-face errors of B (numpy .npz)")
    parser.add_argument("--json", action="store_true", help="print a JSON document")
    parser.set_defaults(run=run)


def errors_file(name: str) -> str:
    """The --errors file: numpy's own rule, ".npz" appended unless the name ends with it."""
    return name if name.endswith(".npz") else name + ".npz"


def run(args: argparse.Namespace) -> int:
    from ..io import read_mesh  # imported here so that --help works without the readers

    errors = None if args.errors is None else errors_file(args.errors)
    prepare_output(errors, [args.a, args.b])
    a = read_mesh(args.a)
    b = read_mesh(args.b)
    started = time.perf_counter()
    result = hausdorff(a, b, samples=args.samples, step=args.step, percentile=args.percentile,
                       relative=args.relative)
    seconds = time.perf_counter() - started
    if errors is not None:
        import numpy as np

        atomic.write_file(errors, lambda stream: np.savez_compressed(
            stream, vertex_error=result.vertex_error, face_error=result.face_error))
    document = result.as_dict()
    document["seconds"] = seconds
    document["a"] = {"path": args.a, "vertices": len(a.vertices), "triangles": len(a.triangles)}
    document["b"] = {"path": args.b, "vertices": len(b.vertices), "triangles": len(b.triangles)}
    if args.json:
        from . import print_json

        print_json(document)
        return 0
    unit = " (fraction of the diagonal)" if args.relative else ""
    print(f"A: {args.a} ({len(a.vertices)} vertices, {len(a.triangles)} triangles)")
    print(f"B: {args.b} ({len(b.vertices)} vertices, {len(b.triangles)} triangles)")
    print(f"diagonal of A: {result.diagonal:.6g}; step {result.step:.4g}; "
          f"samples {result.forward.samples} on A, {result.backward.samples} on B; {seconds:.3f} s")
    print(f"{'':10s}{'max':>14s}{'mean':>14s}{'rms':>14s}{f'p{result.percentile_rank:g}':>14s}{unit}")
    for name in ("forward", "backward", "symmetric"):
        d = getattr(result, name)
        print(f"{name:10s}{d.max:14.6g}{d.mean:14.6g}{d.rms:14.6g}{d.percentile:14.6g}")
    return 0
