"""Blender's own importers and exporters for the batch: .blend, glTF/GLB, FBX and USD (and OBJ, PLY,
STL in, OBJ out, for mesh files whose LODs get baked maps: OBJ's .mtl holds them).

Import clears the scene first (glTF with the importer's "merge vertices": glTF splits vertices
wherever a normal or UV changes) (so one Blender can batch many files); export writes into a
scratch folder inside the output folder and then renames every file it produced into place
(side files such as a .gltf's .bin first, the main file last), so a killed export never leaves
a half-written output under its final name. Options are passed only when the running
Blender's operator has them (3.4 and 4.2 differ): vertex colours, shape keys (morph targets)
and skins (armature + weights) are exported; materials and UVs are by default.
"""

from __future__ import annotations

import os
import shutil
import tempfile

import bpy
from ...core.support import atomic
from ...core.support.errors import TopStocError

IMPORTERS = {"gltf": "gltf", "glb": "gltf", "fbx": "fbx", "usd": "usd", "usda": "usd", "usdc": "usd", "usdz": "usd",
             "obj": "obj", "ply": "ply", "stl": "stl"}
_ADDONS = {"gltf": "io_scene_gltf2", "fbx": "io_scene_fbx"}


def extension(path: str) -> str:
    return os.path.splitext(os.fspath(path))[1].lower().lstrip(".")


def _enable_addon(kind: str) -> None:
    module = _ADDONS.get(kind)
    if module is None:
        return
    import addon_utils

    loaded, enabled = addon_utils.check(module)
    if not enabled:
        addon_utils.enable(module, default_set=True)


def _supported(operator, options: dict) -> dict:
    """The options the operator of this Blender version has."""
    names = {p.identifier for p in operator.get_rna_type().properties}
    return {name: value for name, value in options.items() if name in names}


def _check_usd(path: str) -> None:
    if not bpy.app.build_options.usd:
        raise TopStocError(f"{path}: this Blender ({bpy.app.version_string}) was built without USD; "
                           "use PyPI's bpy or a Blender from blender.org")


def _numpy_alias_for_old_importers() -> None:
    """Blender 3.4's glTF importer uses ``np.bool``, which NumPy 1.24 (Debian 12's) removed: the
    import fails with AttributeError. Restore the alias (it was ``bool``) for those versions."""
    import numpy

    if bpy.app.version < (3, 6, 0) and "bool" not in numpy.__dict__:
        numpy.bool = bool


def _corner_colours_to_points(objects) -> None:
    """Blender < 3.5's glTF exporter reads corner-domain colours by vertex index (a bug: the file
    gets other corners' colours). Before such an export, corner colour attributes whose corners
    agree at every vertex (as after a glTF import) become point attributes: the same colours,
    read right."""
    import numpy

    for obj in objects:
        if obj.type != "MESH":
            continue
        mesh = obj.data
        for attribute in list(mesh.color_attributes):
            if attribute.domain != "CORNER":
                continue
            name, kind = attribute.name, attribute.data_type
            colours = numpy.empty(len(mesh.loops) * 4, dtype=numpy.float32)
            attribute.data.foreach_get("color", colours)
            colours = colours.reshape(-1, 4)
            vertex_of_corner = numpy.empty(len(mesh.loops), dtype=numpy.int64)
            mesh.loops.foreach_get("vertex_index", vertex_of_corner)
            per_vertex = numpy.zeros((len(mesh.vertices), 4), dtype=numpy.float32)
            per_vertex[vertex_of_corner] = colours
            if not numpy.allclose(per_vertex[vertex_of_corner], colours, atol=1e-6):
                continue  # colours differ between a vertex's corners: a point attribute would lose them
            active = mesh.color_attributes.active_color_name if hasattr(mesh.color_attributes, "active_color_name") \
                else None
            mesh.color_attributes.remove(attribute)
            points = mesh.color_attributes.new(name, kind, "POINT")
            points.data.foreach_set("color", per_vertex.ravel())
            if active == name:
                mesh.color_attributes.active_color = points
            mesh.color_attributes.render_color_index = mesh.color_attributes.find(name)


def clear_scene() -> None:
    """Removes every object and the data the importers create."""
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.armatures, bpy.data.materials,
                       bpy.data.actions, bpy.data.images, bpy.data.textures, bpy.data.node_groups,
                       bpy.data.cameras, bpy.data.lights, bpy.data.collections):
        items = list(collection)
        if items:
            bpy.data.batch_remove(items)


def import_file(path: str) -> None:
    """Reads a glTF/GLB, FBX, USD, OBJ, PLY or STL file into an empty scene."""
    kind = IMPORTERS.get(extension(path))
    if kind is None:
        raise TopStocError(f"{path}: not a glTF, FBX, USD, OBJ, PLY or STL file")
    if not os.path.isfile(path):
        raise FileNotFoundError(f"{path}: no such file")
    clear_scene()
    _enable_addon(kind)
    filepath = os.path.abspath(path)
    if kind == "gltf":
        _numpy_alias_for_old_importers()
        # glTF stores one vertex per (position, normal, UV...) combination: merge them back so the
        # surface is connected (corner attributes stay per corner), else flat-shaded or seamed
        # parts fall apart into islands the decimation cannot join.
        operator = bpy.ops.import_scene.gltf
        operator(filepath=filepath, **_supported(operator, {"merge_vertices": True}))
    elif kind == "fbx":
        bpy.ops.import_scene.fbx(filepath=filepath)
    elif kind in ("obj", "ply", "stl"):
        _import_mesh_file(kind, filepath)
    else:
        _check_usd(path)
        bpy.ops.wm.usd_import(filepath=filepath)


def _import_mesh_file(kind: str, filepath: str) -> None:
    """OBJ, PLY or STL with Blender's own importer: the C++ one where this Blender has it (OBJ from
    3.3, PLY from 4.0, STL from 4.1), else the Python add-on's."""
    if f"{kind}_import" in dir(bpy.ops.wm):
        getattr(bpy.ops.wm, f"{kind}_import")(filepath=filepath)
        return
    import addon_utils

    addon_utils.enable(f"io_mesh_{kind}", default_set=True)
    getattr(bpy.ops.import_mesh, kind)(filepath=filepath)


def _export(kind: str, filepath: str, selected: bool, embed_textures: bool = False) -> None:
    _enable_addon(IMPORTERS.get(kind, kind))
    if kind in ("gltf", "glb"):
        if bpy.app.version < (3, 5, 0):
            _corner_colours_to_points(bpy.context.scene.objects)
        operator = bpy.ops.export_scene.gltf
        options = dict(export_format="GLB" if kind == "glb" else "GLTF_SEPARATE", use_selection=selected,
                       export_morph=True, export_skins=True, export_colors=True, export_vertex_color="ACTIVE",
                       export_apply=False)
    elif kind == "fbx":
        operator = bpy.ops.export_scene.fbx
        options = dict(use_selection=selected, add_leaf_bones=False, use_mesh_modifiers=False)
        if embed_textures:  # the images travel inside the file (FBX would name them by absolute path)
            options.update(path_mode="COPY", embed_textures=True)
    elif kind in ("usd", "usda", "usdc", "usdz"):
        _check_usd(filepath)
        operator = bpy.ops.wm.usd_export
        options = dict(selected_objects_only=selected, export_uvmaps=True, export_materials=True,
                       export_armatures=True, export_shapekeys=True)
    elif kind == "obj":
        # The images go next to the output (the baked maps are there already), the .mtl names them so.
        operator = bpy.ops.wm.obj_export
        options = dict(export_selected_objects=selected, export_materials=True, export_uv=True,
                       export_normals=True, apply_modifiers=False, path_mode="COPY")
    else:
        raise TopStocError(f"cannot export .{kind} (Blender formats: blend, gltf, glb, fbx, usd, usda, usdc, usdz; obj)")
    operator(filepath=filepath, **_supported(operator, options))


def save(path: str, objects=None, embed_textures: bool = False) -> list:
    """Writes the scene (or only ``objects`` and what they need) to ``path`` atomically; returns the
    files written (the main file last). A symlink at ``path`` is written through: its target is
    replaced, the link kept. ``embed_textures``: an FBX carries its images inside."""
    path = atomic.target(os.path.abspath(path))
    folder = os.path.dirname(path)
    kind = extension(path)
    os.makedirs(folder, exist_ok=True)
    # Named after the output, so the batch can remove what a killed Blender left (core/batch/run.py).
    scratch = tempfile.mkdtemp(prefix=f".topstoc-partial-{os.path.basename(path)}-", dir=folder)
    try:
        staged = os.path.join(scratch, os.path.basename(path))
        if kind == "blend":
            bpy.context.preferences.filepaths.save_version = 0  # no .blend1 backups
            bpy.ops.wm.save_as_mainfile(filepath=staged, copy=True)
        else:
            selected = objects is not None
            if selected:
                for obj in bpy.context.view_layer.objects:
                    obj.select_set(obj in objects)
            _export(kind, staged, selected, embed_textures)
        if not os.path.exists(staged):
            raise TopStocError(f"{path}: the exporter wrote nothing")
        produced = sorted(name for name in os.listdir(scratch) if name != os.path.basename(path))
        written = []
        for name in produced + [os.path.basename(path)]:
            os.replace(os.path.join(scratch, name), os.path.join(folder, name))
            written.append(os.path.join(folder, name))
        return written
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
