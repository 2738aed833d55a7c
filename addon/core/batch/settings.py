"""Batch settings: the command-line options shared by ``topstoc batch`` and the Blender batch, and
the plain dictionary they become (JSON-able: it keys the manifest and travels to workers and
to the Blender subprocess unchanged).

Targets take one value (one output) or several (a LOD chain ``_LOD0 … _LODn``, one LOD per
value): ``--ratio 1 0.5 0.25``, ``--screen-pixels 800 200 50``. A chain is ordered finest first,
as game engines number LODs: LOD0 is the most detailed, whatever order the values come in.
Screen-size targets (topstoc.core.batch.screen_size) become a max-error target per asset.
"""

from __future__ import annotations

import hashlib
import json
import math

from ..carry.appearance import attribute_weight
from ..api.decimate import ATTRIBUTE_WEIGHT, MODES
from .screen_size import DEFAULT_FOV_DEGREES, DEFAULT_PIXEL_ERROR, DEFAULT_RESOLUTION
from ..support.errors import TopStocError
from ..carry.normal_bake import check_size
from ..cli import clean as clean_cli

TARGET_KINDS = ("ratio", "vertices", "triangles", "max_error", "screen_pixels", "screen_distance")
SCREEN_KINDS = ("screen_pixels", "screen_distance")
#: Blender's own formats (imported and exported by Blender), by extension.
BLENDER_FORMATS = ("blend", "gltf", "glb", "fbx", "usd", "usda", "usdc", "usdz")


#: how each target kind orders a chain finest first: True = larger values are finer
FINER_IS_LARGER = {"ratio": True, "vertices": True, "triangles": True, "screen_pixels": True,
                   "max_error": False, "screen_distance": False}


def add_io_arguments(parser) -> None:
    """--input and --output, the same for ``topstoc batch`` and the Blender batch."""
    parser.add_argument("--input", nargs="+", required=True, metavar="PATH",
                        help="asset files, or folders (searched recursively for supported files): mesh files "
                             "(.obj .ply .off .stl, optionally .gz/.bz2), .blend, .gltf/.glb, .fbx, .usd/.usda/.usdc/.usdz")
    parser.add_argument("--output", required=True, metavar="DIR",
                        help="folder for the outputs (created if missing), named like the inputs "
                             "(<name>_LOD<i> in a chain)")


def add_arguments(parser) -> None:
    """The batch options (everything but --input/--output and the runner's own options)."""
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument("--ratio", type=float, nargs="+", metavar="R",
                        help="fraction of the vertices to keep; several values make a LOD chain, "
                             "ordered finest first (LOD0 the most detailed) whatever their order here")
    target.add_argument("--vertices", type=int, nargs="+", metavar="N", help="output vertex count")
    target.add_argument("--triangles", type=int, nargs="+", metavar="N", help="output triangle count")
    target.add_argument("--max-error", nargs="+", metavar="E[%]",
                        help="largest Hausdorff deviation, absolute or in %% of the bounding-box diagonal")
    target.add_argument("--screen-pixels", type=float, nargs="+", metavar="N",
                        help="LOD for the asset covering N pixels (projected bounding-sphere diameter)")
    target.add_argument("--screen-distance", type=float, nargs="+", metavar="D",
                        help="LOD for the asset seen from distance D (with --fov and --resolution)")
    parser.add_argument("--pixel-error", type=float, default=DEFAULT_PIXEL_ERROR, metavar="PX",
                        help=f"screen targets: allowed deviation in pixels (default {DEFAULT_PIXEL_ERROR:g})")
    parser.add_argument("--fov", type=float, default=DEFAULT_FOV_DEGREES, metavar="DEG",
                        help=f"--screen-distance: vertical field of view (default {DEFAULT_FOV_DEGREES:g})")
    parser.add_argument("--resolution", type=int, default=DEFAULT_RESOLUTION, metavar="ROWS",
                        help=f"--screen-distance: vertical resolution in pixels (default {DEFAULT_RESOLUTION})")
    parser.add_argument("--prune-pixels", type=float, default=0.0, metavar="PX",
                        help="screen targets: drop disconnected parts smaller than PX pixels (default off)")
    parser.add_argument("--lod-files", action="store_true",
                        help="LOD chains: one file per LOD (<name>_LOD<i>.<ext>) instead of all LOD "
                             "objects in one file (mesh files always get one file per LOD)")
    parser.add_argument("--format", metavar="EXT",
                        help="write outputs in this format, e.g. obj, ply, ply.gz, glb (default: the input's, "
                             "uncompressed)")
    parser.add_argument("--bake-normals", type=int, metavar="SIZE",
                        help="bake a SIZE x SIZE tangent-space normal map from each source onto each result (a PNG "
                             "next to the output, used by its materials; margin SIZE/64 px); OBJ, PLY and STL "
                             "files go through Blender then and are written as OBJ (.mtl) or a Blender format")
    parser.add_argument("--bake-colour", action="store_true",
                        help="with --bake-normals: where the result gets a UV map of its own (the source's "
                             "layout is not kept), bake the source's base colour onto it too (a second PNG, "
                             "the materials' base colour), and each image-textured Roughness, Metallic, "
                             "Emission or Alpha (<name>_roughness.png ...)")
    parser.add_argument("--exact-error", action="store_true",
                        help="report each output's exact bracketed Hausdorff max (relative gap 0.1 %%) instead "
                             "of the default bounded estimate (hausdorff: a distance attained; hausdorff_upper: "
                             "a guaranteed upper bound, within 25 %% of it; for sources of 250,000 "
                             "triangles or more the quick bound, with hausdorff_mean: the mean distance, estimated)")
    parser.add_argument("--keep-compression", action="store_true",
                        help="mesh files: a compressed input (.gz, .bz2) gives a compressed output (default: "
                             "uncompressed, which Blender and most tools import)")
    parser.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default 0)")
    parser.add_argument("--adaptivity", type=float, default=0.5, metavar="A",
                        help="0 samples uniformly, 1 follows curvature fully (default 0.5)")
    parser.add_argument("--density", choices=("off", "uniform", "adaptive"), default="off",
                        help="Poisson-disk density control of the samples (default off)")
    parser.add_argument("--mode", choices=MODES, default="quality",
                        help="quality (default): TopStoc then quadric edge collapses; best: quality, then "
                             "large results fitted to the input too (about 1.5x the time); fast: plain TopStoc")
    parser.add_argument("--placement", choices=("subsample", "filtered"), default=None,
                        help="default: set by --mode")
    parser.add_argument("--refine", type=float, default=None, metavar="F",
                        help="0: off; F: TopStoc to F x the target, then quadric collapses (default: set by --mode)")
    parser.add_argument("--attribute-weight", type=float, default=ATTRIBUTE_WEIGHT, metavar="W",
                        help="how much UVs and colours count in quality mode's collapses (mesh files: the "
                             "file's UVs and vertex colours; Blender formats: the active UV map and colour "
                             f"attribute); default {ATTRIBUTE_WEIGHT}, 0 = geometry only")
    parser.add_argument("--symmetry", type=str.upper, choices=("X", "Y", "Z"), metavar="{x,y,z}",
                        help="mirror-symmetric results across the plane through the origin normal to this "
                             "axis (object-local in Blender formats)")
    parser.add_argument("--objects", nargs="+", metavar="NAME",
                        help="Blender formats: objects to decimate (default: every mesh object)")
    parser.add_argument("--clean", action="store_true",
                        help="before decimating, remove small handles and fill small holes as `topstoc clean` "
                             "does, with its options below; the report says what was removed and what was left")
    clean_cli.add_options(parser)


def parse_max_error(text: str) -> tuple:
    """'0.01' -> (0.01, False): absolute; '0.5%' -> (0.005, True): a fraction of the diagonal."""
    text = str(text).strip()
    relative = text.endswith("%")
    try:
        value = float(text.rstrip("%"))
    except ValueError:
        raise TopStocError(f"--max-error must be a number, optionally followed by %, got {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise TopStocError(f"--max-error must be positive, got {text!r}")
    return (value / 100.0, True) if relative else (value, False)


def from_args(args) -> dict:
    """The settings dictionary of parsed arguments; ValueError for inconsistent values."""
    kind = next(k for k in TARGET_KINDS if getattr(args, k) is not None)
    values = list(getattr(args, kind))
    if kind == "max_error":
        values = [parse_max_error(v) for v in values]
    elif kind == "ratio" and not all(0 < v <= 1 for v in values):
        raise TopStocError(f"--ratio values must lie in (0, 1], got {values}")
    elif kind in ("vertices", "triangles") and not all(v >= 1 for v in values):
        raise TopStocError(f"--{kind} values must be positive, got {values}")
    elif kind in SCREEN_KINDS and not all(math.isfinite(v) and v > 0 for v in values):
        raise TopStocError(f"--{kind.replace('_', '-')} values must be positive, got {values}")
    values = finest_first(kind, values)
    if args.prune_pixels and kind not in SCREEN_KINDS:
        raise TopStocError("--prune-pixels needs a screen target (--screen-pixels or --screen-distance)")
    for name in ("pixel_error", "fov", "resolution"):
        if not getattr(args, name) > 0:
            raise TopStocError(f"--{name.replace('_', '-')} must be positive, got {getattr(args, name)}")
    if args.prune_pixels < 0:
        raise TopStocError(f"--prune-pixels must not be negative, got {args.prune_pixels}")
    out_format = None
    if args.format:
        out_format = args.format.lower().lstrip(".")
    optional = {"symmetry": args.symmetry} if args.symmetry else {}  # absent when off: older digests hold
    if getattr(args, "keep_compression", False):
        optional["keep_compression"] = True
    weight = attribute_weight(args.attribute_weight)
    if weight != ATTRIBUTE_WEIGHT:  # absent at the default, likewise
        optional["attribute_weight"] = weight
    if getattr(args, "bake_normals", None) is not None:  # absent when off, likewise
        optional["bake_normals"] = check_size(args.bake_normals)
    if getattr(args, "bake_colour", False):  # absent when off, likewise
        if "bake_normals" not in optional:
            raise TopStocError("--bake-colour needs --bake-normals SIZE (the colour is baked onto the normal "
                               "map's UV map)")
        optional["bake_colour"] = True
    if getattr(args, "exact_error", False):  # absent when off, likewise
        optional["exact_error"] = True
    optional.update(_clean(args))
    return {**optional, "target": kind, "values": values, "chain": len(values) > 1,
            "pixel_error": args.pixel_error, "fov": args.fov, "resolution": args.resolution,
            "prune_pixels": args.prune_pixels, "lod_files": bool(args.lod_files), "format": out_format,
            "options": {"seed": args.seed, "adaptivity": args.adaptivity, "density": args.density,
                        "mode": args.mode, "placement": args.placement, "refine": args.refine},
            "objects": list(args.objects) if args.objects else None}


def _clean(args) -> dict:
    """{"clean": clean()'s keyword arguments} with --clean, {} without (absent: older digests hold)."""
    kwargs = clean_cli.options(args)
    if args.clean:
        return {"clean": kwargs}
    given = [name for name in ("max_handle", "max_hole", "keep_largest") if kwargs[name] is not None]
    if given or not kwargs["fair"]:
        name = given[0].replace("_", "-") if given else "flat"
        raise TopStocError(f"--{name} is an option of --clean; add --clean to clean the assets")
    return {}


def finest_first(kind: str, values: list) -> list:
    """A LOD chain's values ordered finest first (LOD0 the most detailed). --max-error values
    must all be in % or all absolute (the two cannot be ordered without the mesh)."""
    if kind == "max_error":
        if len({relative for _, relative in values}) > 1:
            raise TopStocError("--max-error values of a LOD chain must all be in % or all absolute")
        return sorted(values, key=lambda value: value[0])
    return sorted(values, reverse=FINER_IS_LARGER[kind])


def to_argv(settings: dict) -> list:
    """Command-line arguments that reproduce ``settings`` (for the Blender subprocess)."""
    kind, values = settings["target"], settings["values"]
    if kind == "max_error":
        values = [f"{v * 100!r}%" if relative else repr(v) for v, relative in values]
    argv = [f"--{kind.replace('_', '-')}", *map(str, values),
            "--pixel-error", repr(settings["pixel_error"]), "--fov", repr(settings["fov"]),
            "--resolution", str(settings["resolution"]), "--prune-pixels", repr(settings["prune_pixels"])]
    if settings["lod_files"]:
        argv.append("--lod-files")
    if settings["format"]:
        argv += ["--format", settings["format"]]
    if settings.get("keep_compression"):
        argv.append("--keep-compression")
    if settings.get("exact_error"):
        argv.append("--exact-error")
    for name, value in settings["options"].items():
        if value is not None:  # None: the mode decides
            argv += [f"--{name}", str(value)]
    if settings.get("symmetry"):
        argv += ["--symmetry", settings["symmetry"]]
    if "attribute_weight" in settings:
        argv += ["--attribute-weight", repr(settings["attribute_weight"])]
    if settings["objects"]:
        argv += ["--objects", *settings["objects"]]
    if settings.get("bake_normals"):
        argv += ["--bake-normals", str(settings["bake_normals"])]
    if settings.get("bake_colour"):
        argv.append("--bake-colour")
    if "clean" in settings:
        argv += ["--clean", *clean_cli.to_argv(settings["clean"])]
    return argv


def digest(settings: dict) -> str:
    """A short fingerprint of the settings (part of the manifest key)."""
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def lod_name(name: str, index: int, settings: dict) -> str:
    """``name`` for a single target, ``name_LOD<index>`` in a chain."""
    return f"{name}_LOD{index}" if settings["chain"] else name


def engine_targets(settings: dict, vertices) -> list:
    """One (engine target kwargs, ScreenTarget or None) per LOD for an asset whose vertices
    (world space, all meshes together) are ``vertices``."""
    from .screen_size import screen_target

    kind = settings["target"]
    targets = []
    for value in settings["values"]:
        if kind == "max_error":
            bound, relative = value
            targets.append(({"max_error": bound, "relative": relative}, None))
        elif kind in SCREEN_KINDS:
            screen = screen_target(vertices, pixel_error=settings["pixel_error"], fov_degrees=settings["fov"],
                                   resolution=settings["resolution"],
                                   **{"pixels" if kind == "screen_pixels" else "distance": value})
            targets.append(({"max_error": screen.max_error}, screen))
        elif kind == "ratio":
            targets.append(({"ratio": value}, None))
        else:  # vertices / triangles: counts
            targets.append(({f"target_{kind}": value}, None))
    return targets
