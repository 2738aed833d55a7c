"""One batch asset that is a mesh file (OBJ, PLY, OFF, STL, optionally .gz/.bz2), without Blender.

The file is read in its own vertex order, decimated once per LOD (UV seams and material
borders kept as borders, so UVs, vertex colours and materials carry over exactly), optionally
pruned of small parts (screen targets), measured against the original (a bounded estimate of the
Hausdorff max, or the exact bracketed max with --exact-error) and written atomically
(topstoc.core.api.io.write_mesh: temporary file, then rename). A LOD chain gives one file per
LOD, ``<stem>_LOD<i>.<ext>``.
"""

from __future__ import annotations

import os
import time

from . import settings as batch_settings
from ..api.budget import missed_dict
from ..support.errors import TopStocError
from ..api.error_estimate import estimate_error, exact_error
from ..api.hausdorff import as_surface
from ..api.io import mesh_format, read_mesh
from ..api.job import ATTRIBUTE_WEIGHT
from ..api.mesh_file_job import prepare_file
from .prune import prune_small_parts


def output_paths(path: str, out_dir: str, settings: dict) -> list:
    """The files the asset ``path`` is written to, one per LOD: in the input's format, uncompressed
    unless settings keep compression (or --format names one; a Blender format with --bake-normals)."""
    kind, compression = mesh_format(path)
    compression = compression if settings.get("keep_compression") else None
    name = os.path.basename(os.fspath(path))
    stem = name[:name.lower().rindex("." + kind)]
    if settings["format"] in batch_settings.BLENDER_FORMATS and settings.get("bake_normals"):
        kind, compression = settings["format"], None  # written by Blender (check_bakeable)
    elif settings["format"]:
        kind, compression = mesh_format("x." + settings["format"])
    ext = "." + kind + ("." + compression if compression else "")
    return [os.path.join(out_dir, batch_settings.lod_name(stem, i, settings) + ext)
            for i in range(len(settings["values"]))]


def lod_error(original, result, screen, exact: bool = False, original_surface=None) -> dict:
    """The symmetric Hausdorff error of a LOD (absolute, relative, in pixels): by default a bounded
    estimate (``hausdorff`` attained, ``hausdorff_upper`` guaranteed, within 25 % of it or under 1e-7
    of the diagonal; for big sources the quick bound, with ``hausdorff_mean``), the exact bracketed
    max with ``exact`` (within 0.1 %); ``hausdorff_gap`` names the relative gap asked for
    (topstoc.core.api.error_estimate). original_surface: the original's measurement surface, kept
    across the LODs of one asset."""
    started = time.perf_counter()
    bound = (exact_error if exact else estimate_error)(original, result, original_surface=original_surface)
    diagonal = original_surface.diagonal if original_surface is not None else as_surface(original).diagonal
    entry = {"hausdorff": bound.estimate, "hausdorff_upper": bound.upper,
             "hausdorff_kind": bound.as_dict()["kind"], "hausdorff_gap": bound.gap,
             "hausdorff_converged": bound.converged,
             "hausdorff_relative": bound.estimate / diagonal if diagonal else 0.0,
             "hausdorff_upper_relative": bound.upper / diagonal if diagonal else 0.0,
             "hausdorff_seconds": time.perf_counter() - started}
    if bound.mean == bound.mean:  # the quick bound's mean (NaN for the walks)
        entry["hausdorff_mean"] = bound.mean
    if screen is not None:
        entry["hausdorff_pixels"] = screen.to_pixels(bound.estimate)
        entry["hausdorff_upper_pixels"] = screen.to_pixels(bound.upper)
        entry["screen"] = screen.as_dict()
    return entry


#: The outputs whose materials can reference a baked map, for a mesh file baked through Blender.
BAKED_FORMATS = ("obj", "gltf", "glb", "fbx", "usd", "usda", "usdc", "usdz", "blend")


def check_bakeable(path: str, settings: dict) -> None:
    """TopStocError unless Blender can import the mesh file ``path`` (OFF and compressed PLY/STL/OFF
    through a temporary PLY: blender/batch.py) and its output format has a material to reference
    the baked maps (--bake-normals sends a mesh file through Blender)."""
    kind, compression = mesh_format(path)
    if compression and kind == "obj":  # Blender would find no .mtl beside a decompressed copy
        raise TopStocError(f"{path}: --bake-normals imports OBJ files with Blender, which reads no "
                           f".{compression}: decompress the file (and keep its .mtl beside it) first")
    out = settings["format"] or kind
    if out not in BAKED_FORMATS:
        raise TopStocError(f"{path}: a .{out} output has no material to reference the baked maps: pass "
                           f"--format obj (its .mtl names them), gltf, glb, fbx or usd")


def decimate_mesh_file(path: str, out_dir: str, settings: dict) -> dict:
    """Decimates one mesh file into ``out_dir``; returns its report entry. (With --bake-normals a
    mesh file goes through Blender instead: run.run_asset, blender/batch.py.)"""
    if settings.get("bake_normals"):
        raise TopStocError(f"{path}: --bake-normals runs mesh files through Blender (topstoc batch does)")
    outputs = output_paths(path, out_dir, settings)
    data = read_mesh(path)
    start = time.perf_counter()
    vertices_in, triangles_in, cleaned = data.num_vertices, data.num_triangles, None
    if "clean" in settings:
        data, cleaned = clean_asset(data, settings["clean"])
    options = settings["options"]
    source = prepare_file(path, data, options.get("mode"), options.get("refine"),
                          settings.get("attribute_weight", ATTRIBUTE_WEIGHT))
    lods = []
    surface = as_surface(source.mesh, "original")
    for index, ((target, screen), output) in enumerate(zip(batch_settings.engine_targets(settings, data.vertices),
                                                          outputs)):
        started = time.perf_counter()
        result = source.decimate(target, options, settings.get("symmetry"))
        entry = {"lod": index, "output": output, "target": target, "symmetry": settings.get("symmetry")}
        if screen is not None and settings["prune_pixels"] > 0:
            result, pruned = prune_small_parts(result, settings["prune_pixels"] * screen.world_per_pixel)
            entry["pruned"] = pruned.as_dict()
        bound = getattr(result, "error_bound", None)
        entry.update(vertices=result.num_vertices, triangles=result.num_triangles, repairs=result.stats.repairs,
                     search_error=None if bound is None else float(bound.achieved_error),
                     target_missed=missed_dict(result.stats), topology_kept=result.stats.topology_kept,
                     topology_warning=result.stats.topology_warning,
                     **lod_error(source.mesh, result, screen, settings.get("exact_error", False), surface))
        entry["dropped_attributes"] = source.write(result, output)
        entry["seconds"] = time.perf_counter() - started
        lods.append(entry)
    first = lods[0]
    return {"input": os.fspath(path), "output": first["output"], "outputs": outputs,
            "vertices_in": vertices_in, "triangles_in": triangles_in,
            "vertices_out": first["vertices"], "triangles_out": first["triangles"],
            "seconds": time.perf_counter() - start, "repairs": first["repairs"], "error": first["search_error"],
            "target_missed": first["target_missed"],
            "attributes": source.appearance.channels if source.attribute_kwargs else [],
            "lods": lods, **({} if cleaned is None else {"clean": cleaned})}


def clean_asset(data, kwargs: dict) -> tuple:
    """(the mesh cleaned as ``topstoc clean`` does, attributes carried over; its report: what was
    removed, what was left and why, CleanResult.as_json)."""
    from ..api.clean import clean
    from ..carry.edited_mesh import carried_over

    result = clean(data.vertices, data.triangles, **kwargs)
    return carried_over(data, result.edit), result.as_json()
