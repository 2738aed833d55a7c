"""Batch decimation inside Blender (or PyPI's bpy): mesh files and Blender's own formats (docs/design.md §6).

Mesh files (OBJ, PLY, OFF, STL, optionally .gz/.bz2) go through topstoc.core.batch.mesh_asset (the
same code ``topstoc batch`` runs without Blender); with --bake-normals, mesh files are imported
with Blender's importers (OFF and compressed ones as a temporary PLY) and go the Blender formats' way, written as OBJ (its .mtl names
the maps) or a Blender format (mesh_asset.check_bakeable says why others are refused). .blend files are opened; glTF/GLB, FBX and
USD are imported with Blender's importers into an empty scene. Their mesh objects (all, or
those named with --objects) are decimated with the add-on's pipeline (the Guided Decimate
operator's: guidance stored on the objects, UVs, colours, materials, vertex groups and
whatever else the pipeline carries) and the scene is written back with Blender's exporter
(the input's format, or --format), atomically. A LOD chain (several target values) makes
objects ``<name>_LOD0 … _LODn`` next to each source object (which is then removed), all in one
file, or one file per LOD (``<stem>_LOD<i>.<ext>``) with --lod-files. Screen-size targets use
the bounding sphere of all decimated meshes in world space (the asset's screen size). One
progress line per input, a JSON report (per LOD: counts and the measured Hausdorff error),
exit code 1 when any input failed (the others are still processed).
"""

from __future__ import annotations

import os
import sys
import tempfile
import traceback
from types import SimpleNamespace

import numpy as np

from ..core.batch import settings as batch_settings
from ..core.batch.mesh_asset import check_bakeable, decimate_mesh_file, lod_error
from ..core.api.budget import missed_dict, report_missed, report_topology
from ..core.api.decimate import ATTRIBUTE_WEIGHT
from ..core.batch.prune import prune_small_parts
from ..core.batch.run import misnamed_failure, utf8_name, write_report
from ..core.support.errors import TopStocError, one_line, shown_path
from ..core.api.hausdorff import as_surface
from ..core.api.io import mesh_format, read_mesh, write_mesh
from ..core.support.output_guard import check_folders, prepare_output, output_folder

BLEND = ".blend"


def parse_args(argv):
    from ..core.cli.messages import ArgumentParser

    parser = ArgumentParser(
        prog="blender -b --python topstoc/batch.py --",
        description="Decimate mesh files, .blend, glTF/GLB, FBX and USD files with TopStoc.")
    parser.command = "topstoc batch"  # errors as topstoc batch prints them
    batch_settings.add_io_arguments(parser)  # files and folders, as topstoc batch takes them
    parser.add_argument("--json", metavar="REPORT.json", help="write the report here")
    batch_settings.add_arguments(parser)
    return parser.parse_args(argv)


def _panel(settings: dict):
    """A panel for the pipeline (pipeline.decimate_options reads it): the batch's options, symmetry
    and attribute weight; the target is passed explicitly."""
    axis = settings.get("symmetry")
    return SimpleNamespace(target_mode="RATIO", use_symmetry=axis is not None, symmetry_axis=axis or "X",
                           attribute_weight=settings.get("attribute_weight", ATTRIBUTE_WEIGHT), **settings["options"])


def _bone_shapes(bpy) -> set:
    """Meshes drawn as bones (e.g. the glTF importer's "Icosphere"): not part of the asset."""
    return {bone.custom_shape.name for obj in bpy.context.scene.objects if obj.type == "ARMATURE" and obj.pose
            for bone in obj.pose.bones if bone.custom_shape is not None}


def _mesh_objects(bpy, path: str, names) -> list:
    shapes = _bone_shapes(bpy)
    objects = [o for o in bpy.context.scene.objects if o.type == "MESH" and o.name not in shapes]
    if names:
        missing = [name for name in names if bpy.data.objects.get(name) is None]
        if missing:
            raise TopStocError(f"{path}: no object named {', '.join(repr(m) for m in missing)}")
        objects = [bpy.data.objects[name] for name in names]
        wrong = [o.name for o in objects if o.type != "MESH"]
        if wrong:
            raise TopStocError(f"{path}: {', '.join(wrong)} is not a mesh object")
    if not objects:
        raise TopStocError(f"{path}: no mesh objects")
    return objects


def _world_vertices(objects) -> np.ndarray:
    """Every vertex of ``objects`` in world space (for the asset's bounding sphere)."""
    from .io import mesh_read

    chunks = []
    for obj in objects:
        local = mesh_read.read_positions(obj.data).astype(np.float64)
        matrix = np.array(obj.matrix_world, dtype=np.float64)
        chunks.append(local @ matrix[:3, :3].T + matrix[:3, 3])
    return np.concatenate(chunks) if chunks else np.zeros((0, 3))


def _world_scale(obj) -> float:
    """Largest scale factor of the object's world matrix: local lengths x this = world lengths."""
    return float(max(abs(s) for s in obj.matrix_world.to_scale())) or 1.0


def _copy_armature_modifiers(source, target) -> None:
    """A LOD object must deform like its source for skinned export: copy Armature modifiers when
    the pipeline did not already copy the source's modifiers."""
    if len(target.modifiers):
        return
    for modifier in source.modifiers:
        if modifier.type == "ARMATURE":
            copy = target.modifiers.new(modifier.name, "ARMATURE")
            copy.object = modifier.object
            copy.use_vertex_groups = modifier.use_vertex_groups
            copy.use_bone_envelopes = modifier.use_bone_envelopes


def _bake(bpy, source, result, settings, name: str) -> dict:
    """Bakes the normal map asked for (--bake-normals) from ``source`` onto ``result`` as
    ``<output folder>/<name>_normal.png``, and with --bake-colour the base colour as
    ``<name>_color.png`` where the result got a UV map of its own, with the source's other
    image-textured channels as ``<name>_roughness.png`` … (bake_channels.py); returns the report's
    entries (``normal_map``, ``colour_map``: its path, or None where the source's UV layout was
    kept; ``roughness_map`` … for each channel baked)."""
    from .decimation import bake

    size = settings["bake_normals"]
    colour = bool(settings.get("bake_colour"))
    baked = bake.bake_normals(bpy.context, source, result, size=size, margin=bake_margin(size), store="FILE",
                              folder=settings["bake_folder"], name=name, replace=True, colour=colour)
    maps = {"normal_map": baked.path}
    if colour:
        maps["colour_map"] = baked.colour_path or None
        maps.update({f"{kind}_map": path for kind, path in (baked.channel_paths or {}).items()})
    if baked.colour_path and settings["bake_format"] in ("gltf", "glb"):
        maps["dropped_colour_attributes"] = _drop_colour_attributes(result)
    return maps


def _drop_colour_attributes(result) -> list:
    """Removes ``result``'s colour attributes, returning their names: glTF multiplies the base
    colour by the vertex colours (COLOR_0), and its base colour is now the baked texture."""
    attributes = result.data.color_attributes
    names = [attribute.name for attribute in attributes]
    for name in names:
        attributes.remove(attributes[name])
    return names


def bake_margin(size: int) -> int:
    """The batch's bleed around UV islands: 16 pixels at 1024."""
    return max(2, size // 64)


def _write_in_place(bpy, pipeline, obj, run, settings, name: str):
    """The pipeline's IN_PLACE write; with --bake-normals the original mesh is kept on a
    temporary object to bake from, then removed. Returns _bake's report entries ({} without)."""
    if not settings.get("bake_normals"):
        pipeline.write_output(run, "IN_PLACE")
        return {}
    original = obj.data
    holder = bpy.data.objects.new(f"{obj.name} (original)", original)
    bpy.context.scene.collection.objects.link(holder)
    holder.matrix_world = obj.matrix_world.copy()
    try:
        pipeline.write_output(run, "IN_PLACE")
        return _bake(bpy, holder, obj, settings, name)
    finally:
        bpy.data.objects.remove(holder)
        if original.users == 0:
            mesh_name = original.name
            bpy.data.meshes.remove(original)
            obj.data.name = mesh_name


def _decimate_object(bpy, pipeline, obj, settings, targets) -> tuple:
    """Decimates one object once per LOD; returns (report entry, LOD objects)."""
    scale = _world_scale(obj)
    n = len(obj.data.vertices)
    lods, lod_objects, surfaces = [], [], {}  # surfaces: the original's, measured once for all LODs
    for index, (target, screen) in enumerate(targets):
        if screen is not None:  # world units -> the object's own units
            target = {"max_error": target["max_error"] / scale}
        run = pipeline.decimate(bpy.context, obj, _panel(settings), target=target)
        entry = {"lod": index, "target": target, "symmetry": settings.get("symmetry")}
        if screen is not None and settings["prune_pixels"] > 0:
            run.result, pruned = prune_small_parts(run.result, settings["prune_pixels"] * screen.world_per_pixel / scale)
            entry["pruned"] = pruned.as_dict()
        bound = getattr(run.result, "error_bound", None)
        if id(run.prepared.mesh) not in surfaces:
            surfaces[id(run.prepared.mesh)] = as_surface(run.prepared.mesh, "original")
        error = lod_error(run.prepared.mesh, run.result, None, settings.get("exact_error", False),
                          surfaces[id(run.prepared.mesh)])
        error["hausdorff_world"] = error["hausdorff"] * scale
        if screen is not None:
            error["hausdorff_pixels"] = screen.to_pixels(error["hausdorff_world"])
            error["hausdorff_upper_pixels"] = screen.to_pixels(error["hausdorff_upper"] * scale)
            error["screen"] = screen.as_dict()
        entry.update(vertices=run.result.num_vertices, triangles=run.result.num_triangles,
                     repairs=run.result.stats.repairs, seconds=run.seconds, target_missed=missed_dict(run.result.stats),
                     topology_kept=run.result.stats.topology_kept, topology_warning=run.result.stats.topology_warning,
                     search_error=None if bound is None else float(bound.achieved_error), **error)
        if settings["chain"]:
            name = batch_settings.lod_name(obj.name, index, settings)
            lod = pipeline.write_output(run, "NEW_OBJECT", name=name)
            lod.name = name  # the source keeps its name until it is removed below
            if settings.get("bake_normals"):
                entry.update(_bake(bpy, obj, lod, settings, f"{settings['bake_stem']}_{name}"))
            _copy_armature_modifiers(obj, lod)
            entry["object"] = lod.name
            lod_objects.append(lod)
        else:
            maps = _write_in_place(bpy, pipeline, obj, run, settings, f"{settings['bake_stem']}_{obj.name}")
            entry.update(maps)
        lods.append(entry)
    report = {"object": obj.name, "vertices_in": n, "vertices_out": lods[0]["vertices"],
              "triangles_out": lods[0]["triangles"], "seconds": sum(lod["seconds"] for lod in lods),
              "repairs": lods[0]["repairs"], "error": lods[0]["search_error"],
              "target_missed": lods[0]["target_missed"], "lods": lods}
    return report, lod_objects


def _rename_chain(bpy, sources, chains) -> None:
    """Removes the sources of a LOD chain and gives their LODs the final ``<name>_LOD<i>`` names."""
    for source, lods in zip(sources, chains):
        name = source.name
        children = list(source.children)
        mesh = source.data
        bpy.data.objects.remove(source)
        if mesh.users == 0:
            bpy.data.meshes.remove(mesh)
        for index, lod in enumerate(lods):
            lod.name = f"{name}_LOD{index}"
        for child in children:  # children of a removed source hang under its LOD0
            if lods:
                child.parent = lods[0]


def decimate_scene_file(path: str, out_dir: str, settings: dict) -> dict:
    """Decimates the mesh objects of a .blend, glTF/GLB, FBX or USD file and writes the result."""
    import bpy

    from .decimation import pipeline
    from .io import scene_files as scene_io

    if not os.path.isfile(path):
        raise FileNotFoundError(f"{path}: no such file")
    if path.lower().endswith(BLEND):
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    elif _is_mesh_file(path):
        _import_mesh_file(scene_io, path)
    else:
        scene_io.import_file(path)
    objects = _mesh_objects(bpy, path, settings["objects"])
    cleaned = _clean_objects(objects, settings["clean"]) if "clean" in settings else {}
    stem, ext = _output_name(path, settings)
    settings = dict(settings, bake_folder=out_dir, bake_stem=stem, bake_format=ext.lstrip(".").lower())
    if _is_mesh_file(path):  # a chain writes one file per LOD, as without Blender (mesh_asset.output_paths)
        settings["lod_files"] = True
    asset = _world_vertices(objects)
    targets = batch_settings.engine_targets(settings, asset)
    entries, chains, sources = [], [], []
    done = set()
    for obj in objects:
        if obj.data.name in done and not settings["chain"]:  # a shared mesh is decimated once
            continue
        done.add(obj.data.name)
        entry, lod_objects = _decimate_object(bpy, pipeline, obj, settings, targets)
        if obj.data.name in cleaned:  # counts in: the mesh before its clean-up
            entry["vertices_in"], entry["clean"] = cleaned[obj.data.name]
        entries.append(entry)
        if settings["chain"]:
            sources.append(obj)
            chains.append(lod_objects)
    if settings["chain"]:
        _rename_chain(bpy, sources, chains)
        for entry, lods in zip(entries, chains):
            for lod_entry, lod in zip(entry["lods"], lods):
                lod_entry["object"] = lod.name

    outputs = []
    embed = bool(settings.get("bake_normals"))  # an FBX then carries its baked maps
    if settings["chain"] and settings["lod_files"]:
        others = [o for o in bpy.context.scene.objects if o.type != "MESH"]  # armatures, empties
        for index in range(len(targets)):
            lod_set = [lods[index] for lods in chains] + others
            outputs.append(scene_io.save(os.path.join(out_dir, f"{stem}_LOD{index}{ext}"), lod_set,
                                         embed_textures=embed)[-1])
    else:
        outputs.append(scene_io.save(os.path.join(out_dir, stem + ext), embed_textures=embed)[-1])
    return {"input": path, "output": outputs[0], "outputs": outputs,
            "vertices_in": sum(e["vertices_in"] for e in entries),
            "vertices_out": sum(e["vertices_out"] for e in entries),
            "triangles_out": sum(e["triangles_out"] for e in entries),
            "seconds": sum(e["seconds"] for e in entries), "error": None, "objects": entries}


def _output_name(path: str, settings: dict) -> tuple:
    """(stem, .ext) of the outputs: the input's name (a mesh file's without its format and compression,
    as mesh_asset.output_paths names them) and --format's extension or the input's."""
    name = os.path.basename(path)
    if _is_mesh_file(path):
        kind, _ = mesh_format(path)
        stem, ext = name[:name.lower().rindex("." + kind)], "." + kind
    else:
        stem, ext = os.path.splitext(name)
    return stem, "." + settings["format"] if settings["format"] else ext


def _import_mesh_file(scene_io, path: str) -> None:
    """A mesh file into an empty scene with Blender's importer; OFF (Blender has no importer) and
    compressed PLY/STL/OFF are read with the project's reader and imported as a temporary PLY."""
    kind, compression = mesh_format(path)
    if kind != "off" and not compression:
        scene_io.import_file(path)
        return
    with tempfile.TemporaryDirectory(prefix="topstoc-mesh-") as scratch:
        copy = os.path.join(scratch, _output_name(path, {"format": "ply"})[0] + ".ply")  # objects keep the stem
        write_mesh(copy, read_mesh(path))
        scene_io.import_file(copy)


def _clean_objects(objects, kwargs: dict) -> dict:
    """Cleans each mesh as ``topstoc clean`` does (a shared mesh once), in place, attributes
    carried over; returns (vertices before, CleanResult.as_json) by mesh name."""
    from ..core.api.clean import clean
    from .io import mesh_edit, mesh_read

    reports = {}
    for obj in objects:
        if obj.data.name in reports:
            continue
        name = obj.data.name
        arrays = mesh_read.read_mesh(obj.data)
        result = clean(arrays.vertices, arrays.triangles, **kwargs)
        mesh_edit.apply_edit(obj, arrays, result.edit)
        reports[name] = (len(arrays.vertices), result.as_json())
    return reports


def _register_addon() -> None:
    """Blender formats read the guidance settings of the scene and objects: register the add-on."""
    import bpy

    from .. import register

    if not hasattr(bpy.types.Object, "topstoc"):
        register()


def _is_mesh_file(path: str) -> bool:
    from ..core.batch.run import asset_kind

    return asset_kind(path) == "mesh"


def main(argv=None) -> int:
    if argv is None:
        argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        args = parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    from ..core.batch.run import find_inputs

    try:
        settings = batch_settings.from_args(args)
        inputs = find_inputs(args.input)
        if not inputs:
            raise TopStocError("no input assets found")
        check_folders(args.input, args.output)
        prepare_output(args.json, inputs)
        output_folder(args.output)
    except (ValueError, OSError) as error:
        print(f"topstoc batch: error: {one_line(error)}", file=sys.stderr, flush=True)
        return 1
    report = {"results": [], "failures": []}
    total = len(inputs)
    for i, path in enumerate(inputs, 1):
        prefix = f"topstoc batch [{i}/{total}] {shown_path(path)}"
        if not utf8_name(path):
            report["failures"].append(misnamed_failure(path))
            print(f"{prefix}: FAILED: {report['failures'][-1]['message']}", file=sys.stderr, flush=True)
            continue
        print(f"{prefix}: decimating ...", flush=True)
        try:
            if _is_mesh_file(path) and not settings.get("bake_normals"):
                entry = decimate_mesh_file(path, args.output, settings)
            else:
                if _is_mesh_file(path):  # baked maps: imported, decimated, baked and exported by Blender
                    check_bakeable(path, settings)
                _register_addon()
                entry = decimate_scene_file(path, args.output, settings)
        except Exception as error:  # one broken input must not stop the batch
            message = _failure_message(error)
            report["failures"].append({"input": path, "message": message})
            print(f"{prefix}: FAILED: {message}", file=sys.stderr, flush=True)
            continue
        report["results"].append(entry)
        print(f"{prefix}: {entry['vertices_in']} -> {entry['vertices_out']} vertices, "
              f"{entry['triangles_out']} triangles in {entry['seconds']:.3f} s -> {entry['output']}"
              + "".join("; " + phrase for phrase in report_missed(entry) + report_topology(entry)), flush=True)
    if args.json:
        write_report(args.json, report)
    print(f"topstoc batch: {len(report['results'])} done, {len(report['failures'])} failed", flush=True)
    return 1 if report["failures"] else 0


def _failure_message(error: Exception) -> str:
    """One line for a failed input: an importer's or exporter's own traceback shortened to its
    last line; a traceback printed only for errors nobody raised on purpose."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    message = one_line(error)
    if "Traceback" in message and len(lines) > 1:
        message = "Blender: " + lines[-1]
    message = message[len("Error: "):] if message.startswith("Error: ") else message  # bpy.ops
    if not isinstance(error, (ValueError, OSError, RuntimeError)):
        traceback.print_exc()
    return message
