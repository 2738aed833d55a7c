"""``clean IN OUT``: remove small handles and tunnels, fill small holes (docs/design.md §4.6, §6).

Writes the cleaned mesh (attributes carried over as by the edit subcommands) and prints what
was removed and what was left and why; with --json the document of ``CleanResult.as_json``
plus the input, output and the new mesh's topology.
"""

from __future__ import annotations

from . import print_json, subcommand
from ..support.errors import TopStocError
from ..support.output_guard import add_overwrite_argument, prepare_output

#: Lines of removed and left items printed without --json.
SHOWN = 40


def add_parser(subparsers) -> None:
    parser = subcommand(
        subparsers, "clean", "remove small handles and tunnels, fill small holes",
        "Remove every handle or tunnel whose shortest loop is below a size (cutting along the "
        "shorter of its handle and tunnel loop and closing both sides) and fill every hole whose "
        "border is below a size, with patches refined and faired into the surface; the rest of "
        "the surface is left exactly as it was. Sizes are lengths, or percentages of the bounding "
        "box's diagonal like 1%%.",
        ("input", "IN", "input mesh file"),
        ("output", "OUT", "output mesh file"))
    add_options(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON report")
    add_overwrite_argument(parser)
    parser.set_defaults(run=run)


def add_options(parser) -> None:
    """The clean-up's sizes and patch style, the same for ``topstoc clean`` and ``batch --clean``."""
    parser.add_argument("--max-handle", metavar="SIZE", default=None,
                        help="remove handles whose shortest loop is shorter (default 1%% of the diagonal; 0: none)")
    parser.add_argument("--max-hole", metavar="SIZE", default=None,
                        help="fill holes whose border is shorter (default 1%% of the diagonal; 0: none)")
    parser.add_argument("--keep-largest", type=int, metavar="N",
                        help="keep the N largest handles (with no --max-handle, remove all others)")
    parser.add_argument("--flat", action="store_true", help="flat patches with the border's vertices only")


def options(args) -> dict:
    """The keyword arguments of ``topstoc.core.api.clean.clean`` given by the parsed options
    (JSON-able: the batch keeps them in its settings)."""
    if args.keep_largest is not None and args.keep_largest < 0:
        raise TopStocError(f"--keep-largest must be 0 or more, got {args.keep_largest}")
    return {"max_handle": args.max_handle, "max_hole": args.max_hole, "keep_largest": args.keep_largest,
            "fair": not args.flat}


def to_argv(kwargs: dict) -> list:
    """Options that reproduce ``kwargs`` (an ``options`` result)."""
    argv = []
    for name in ("max_handle", "max_hole", "keep_largest"):
        if kwargs[name] is not None:
            argv += ["--" + name.replace("_", "-"), str(kwargs[name])]
    return argv + ([] if kwargs["fair"] else ["--flat"])


def run(args) -> int:
    from ..api.clean import clean
    from ..api.io import read_mesh, write_mesh
    from ..api.topology import topology
    from ..carry.edited_mesh import carried_over

    kwargs = options(args)
    prepare_output(args.output, [args.input], overwrite=args.overwrite)
    data = read_mesh(args.input)
    result = clean(data.vertices, data.triangles, **kwargs)
    write_mesh(args.output, carried_over(data, result.edit))
    info = topology(result.vertices, result.triangles)
    if args.json:
        report = {"input": args.input, "output": args.output}
        report.update(info.to_dict())
        report["clean"] = result.as_json()
        print_json(report)
        return 0
    added = len(result.triangles) - len(data.triangles)
    print(f"{args.output}: {len(result.vertices)} vertices, {len(result.triangles)} triangles ({added:+d}), "
          f"{info.summary()}")
    handles = result.count("handle") + result.count("tunnel")
    print(f"  removed {handles} handles ({result.count('handle')} cut, {result.count('tunnel')} tunnels filled) "
          f"below {result.max_handle:.6g}, genus {result.genus_before} -> {result.genus_after}; "
          f"filled {result.count('hole')} holes below {result.max_hole:.6g}; "
          f"worst patch aspect {result.patch_aspect:.3g}; {result.seconds['total']:.3f} s")
    def removed_line(item) -> str:
        return (f"  removed {item.kind}: {item.edges} edges, length {item.loop_length:.6g}, patch area "
                f"{item.patch_area:.6g}, aspect {item.patch_aspect:.3g} ({item.patch})")

    # Handles first, then what was left, then the (often many) holes.
    lines = [removed_line(item) for item in result.removed if item.kind != "hole"]
    lines += [f"  left {item.kind}{f' length {item.loop_length:.6g}' if item.loop_length > 0 else ''}: "
              f"{item.reason}" for item in result.left]
    lines += [removed_line(item) for item in result.removed if item.kind == "hole"]
    for line in lines[:SHOWN]:
        print(line)
    if len(lines) > SHOWN:
        print(f"  ... and {len(lines) - SHOWN} more (--json lists every one)")
    return 0
