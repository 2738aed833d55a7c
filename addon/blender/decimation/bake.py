"""A tangent-space normal map baked from a source object onto its decimated result (Cycles, CPU,
selected-to-active), so a low LOD still shades like the sculpt.

The result keeps its UV map (the decimation keeps UV seams exactly) when every texel of it belongs
to one place of the surface, else gets one from Blender's Smart UV Project with island gaps sized
for the resolution. The rays reach from the measured Hausdorff distance between the two
(core/carry/normal_bake.py). Where Cycles bakes nothing (Debian's Blender 3.4), the same rays are cast
by bake_raycast.py. The image is saved beside the .blend
(or a given folder) or packed, and the result gets copies of its materials with an Image Texture
and a Normal Map node feeding the shader's Normal input; the source's materials are untouched.
The user's render engine, bake settings, selection, active object and visibility are restored.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass

import bpy
import numpy as np

from ...core.support.errors import TopStocError
from ...core.api.hausdorff import hausdorff
from ...core.carry.normal_bake import (MAX_OVERLAP, available_memory, check_memory, check_size, island_margin,
                                       overlap_fraction, ray_reach)
from . import bake_channels, bake_colour, bake_raycast
from ..io import edge_flags, mesh_read
from ..io.mesh_access import read_array

BAKE_UV_NAME = "TopStoc Bake"  #: the UV map made when the result has no usable one
HAUSDORFF_SAMPLES = 200_000
NODE_LABEL = "TopStoc Normal Map"
DETAIL = 1e-3  #: surfaces farther apart than this x the diagonal must give a map that is not flat


class BakeError(TopStocError):
    """A bake that cannot run (one line for the status bar / batch log)."""


@dataclass
class Baked:
    """A finished bake."""

    image: bpy.types.Image
    uv_map: str              #: the UV map the image is laid out on
    unwrapped: bool          #: True when the UV map was made for the bake
    hausdorff_max: float     #: world units
    extrusion: float         #: cage extrusion (world units)
    max_ray: float           #: max ray distance (world units)
    method: str = "Cycles"   #: "Cycles", or "ray cast" where this Blender's Cycles baked nothing
    path: str = ""           #: the saved file ("" when packed)
    colour: object = None    #: the base colour image (bake_colour.py), or None
    colour_path: str = ""    #: its saved file ("" when packed or not baked)
    channels: dict = None    #: {"roughness": image, …}: the source's other image-textured channels (bake_channels.py)
    channel_paths: dict = None  #: {"roughness": saved file, …} (empty when packed)


def check_bakeable(source, result) -> None:
    """One-line errors for what a bake cannot use: non-meshes, a source without faces, modifiers
    (but Armature ones: the bake uses the rest pose)."""
    for obj in (source, result):
        mesh_read.check_mesh_object(obj, BakeError)
    if len(source.data.polygons) == 0:
        raise BakeError(f"'{source.name}' has no faces to bake a normal map from")
    if len(result.data.polygons) == 0:
        raise BakeError(f"'{result.name}' has no faces to bake a normal map onto")
    for obj in (source, result):
        live = [m.name for m in obj.modifiers if (m.show_render or m.show_viewport) and m.type != "ARMATURE"]
        if live:
            raise BakeError(f"'{obj.name}' has modifiers that are not applied ({', '.join(live)}): apply or "
                            f"disable them before baking normals")


def _world_triangles(obj, matrix) -> tuple:
    arrays = mesh_read.read_mesh(obj.data)
    m = np.array(matrix, dtype=np.float64)
    return arrays.vertices @ m[:3, :3].T + m[:3, 3], arrays.triangles


def measure_reach(source, result) -> tuple:
    """(Hausdorff max, bounding-box diagonal, extrusion, max ray distance) in world units, both
    meshes placed where the source is (the result is baked there)."""
    a = _world_triangles(source, source.matrix_world)
    b = _world_triangles(result, source.matrix_world)
    measured = hausdorff(a, b, samples=HAUSDORFF_SAMPLES, percentile=0)
    distance = measured.symmetric.max_upper
    if not np.isfinite(distance):
        distance = measured.symmetric.max
    return (distance, measured.diagonal, *ray_reach(distance, measured.diagonal))


def uv_triangles(mesh, layer) -> np.ndarray:
    """(m, 3, 2) UV coordinates of the mesh's loop triangles in ``layer``."""
    mesh.calc_loop_triangles()
    loops = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    layer.data.foreach_get("uv", uv)
    return uv.reshape(-1, 2)[loops].reshape(-1, 3, 2)


def ensure_uv_map(obj, size: int, margin: int) -> tuple:
    """(name of the UV map the bake uses, True when made now): the active one when every texel of
    its layout belongs to one place of the surface, else a new one from Smart UV Project (made
    active for the bake; the others stay). ``obj`` must be the only selected object and the active
    one (Edit Mode edits them all)."""
    uv_layers = obj.data.uv_layers
    active = uv_layers.active
    if active is not None and overlap_fraction(uv_triangles(obj.data, active)) <= MAX_OVERLAP:
        return active.name, False
    layer = uv_layers.get(BAKE_UV_NAME) or uv_layers.new(name=BAKE_UV_NAME)
    if layer is None:
        raise BakeError(f"'{obj.name}' has no room for another UV map (Blender allows 8)")
    uv_layers.active = layer
    name = layer.name  # Edit Mode rebuilds the layers: this reference goes stale (Blender 3.4)
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        bpy.ops.mesh.reveal()
        bpy.ops.mesh.select_all(action="SELECT")
        bpy.ops.uv.smart_project(island_margin=island_margin(margin, size))
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    return name, True


def own_normals(result):
    """Gives ``result`` (the only selected object and the active one) its own smooth normals, no
    custom normals and no sharp edges: the decimation carried the source's custom normals (its
    detail sampled at the LOD's few corners, and sharp edges wherever those differ), which tilt
    the bake's rays and tangent frames; the map carries the source's shading instead, hard edges
    included. Returns what restore_normals puts back (None: nothing changed)."""
    mesh = result.data
    normals = mesh_read.read_custom_normals(mesh)
    sharp = read_array(mesh.edges, "use_edge_sharp", len(mesh.edges), 1, bool)
    angle = getattr(mesh, "auto_smooth_angle", None)  # Blender < 4.1 splits normals at wider angles
    if normals is None and not sharp.any() and (angle is None or not mesh.use_auto_smooth or angle >= np.pi):
        return None
    if normals is not None:
        bpy.ops.mesh.customdata_custom_splitnormals_clear()
    if angle is not None:
        mesh.auto_smooth_angle = np.pi
    edge_flags.write_edge_flags(mesh, {"use_edge_sharp": np.zeros(len(sharp), dtype=bool)})
    return normals, angle, sharp


def restore_normals(result, saved) -> None:
    """Puts back the custom normals and sharp edges own_normals took from ``result``."""
    if saved is None:
        return
    normals, angle, sharp = saved
    if angle is not None:
        result.data.auto_smooth_angle = angle
    if normals is not None:
        result.data.normals_split_custom_set(normals)
    edge_flags.write_edge_flags(result.data, {"use_edge_sharp": sharp})


def new_image(name: str, size: int) -> bpy.types.Image:
    """A flat tangent-space normal map (0.5, 0.5, 1) of ``size``², non-colour data."""
    image = bpy.data.images.new(name, size, size, alpha=False, float_buffer=False)
    image.generated_color = (0.5, 0.5, 1.0, 1.0)
    image.colorspace_settings.name = "Non-Color"
    return image


def _shader_node(tree):
    """The node whose "Normal" input the map feeds: the output's surface shader (Principled)."""
    for node in tree.nodes:
        if node.type == "OUTPUT_MATERIAL" and node.is_active_output and node.inputs["Surface"].links:
            shader = node.inputs["Surface"].links[0].from_node
            if "Normal" in shader.inputs:
                return shader
    return next((node for node in tree.nodes if node.type == "BSDF_PRINCIPLED"), None)


def _new_material(name: str):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    return material


def wire_normal_map(material, image, uv_map: str) -> None:
    """Adds an Image Texture (``image``, the active node: the bake writes into it) and a Normal Map
    node on ``uv_map`` to ``material``, feeding its shader's Normal input; nothing else changes."""
    material.use_nodes = True
    tree = material.node_tree
    shader = _shader_node(tree)
    if shader is None:
        raise BakeError(f"material '{material.name}' has no shader with a Normal input to wire the map to")
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    texture.label = NODE_LABEL
    texture.location = (shader.location.x - 600, shader.location.y - 300)
    coordinates = tree.nodes.new("ShaderNodeUVMap")  # the map's own UV map, whichever renders
    coordinates.uv_map = uv_map
    coordinates.location = (shader.location.x - 800, shader.location.y - 300)
    tree.links.new(coordinates.outputs["UV"], texture.inputs["Vector"])
    normal = tree.nodes.new("ShaderNodeNormalMap")
    normal.space = "TANGENT"
    normal.uv_map = uv_map
    normal.location = (shader.location.x - 250, shader.location.y - 300)
    tree.links.new(texture.outputs["Color"], normal.inputs["Color"])
    tree.links.new(normal.outputs["Normal"], shader.inputs["Normal"])
    for node in tree.nodes:
        node.select = node is texture
    tree.nodes.active = texture


def give_materials(result, image, uv_map: str) -> list:
    """Replaces the result's materials by copies (``<name>_TopStoc``) wired to the map; a result
    without materials gets a new one. Returns the materials made."""
    made, copies = [], {}
    if not any(slot.material for slot in result.material_slots):
        material = _new_material(f"{result.name}_TopStoc")
        if len(result.material_slots) == 0:
            result.data.materials.append(material)
        for slot in result.material_slots:
            slot.material = material
        copies[None] = material
    for slot in result.material_slots:
        if slot.material is None or slot.material in copies.values():
            continue
        if slot.material.name not in copies:
            copies[slot.material.name] = slot.material.copy()
            copies[slot.material.name].name = f"{slot.material.name}_TopStoc"
        slot.material = copies[slot.material.name]
    for material in copies.values():
        wire_normal_map(material, image, uv_map)
        made.append(material)
    return made


class _SceneState:
    """The render engine, Cycles device and samples, selection, active object, visibility, the
    result's placement and the Armature modifiers (off while baking), put back when the ``with``
    block ends, whatever happens in it."""

    def __init__(self, context, source, result):
        self.context, self.source, self.result = context, source, result
        self.engine = context.scene.render.engine
        self.selected = [obj for obj in context.view_layer.objects if obj.select_get()]
        self.active = context.view_layer.objects.active
        self.hidden = {obj: (obj.hide_get(), obj.hide_viewport, obj.hide_select) for obj in (source, result)}
        self.matrix = result.matrix_basis.copy()
        self.cycles = None
        self.armatures = {m: (m.show_viewport, m.show_render) for obj in (source, result)
                          for m in obj.modifiers if m.type == "ARMATURE"}

    def __enter__(self):
        for modifier in self.armatures:  # skinned: both baked in their rest pose, as their meshes are
            modifier.show_viewport = modifier.show_render = False
        for obj in self.hidden:
            obj.hide_set(False)
            obj.hide_viewport = obj.hide_select = False
        self.context.view_layer.update()  # matrix_world of objects moved since the last update
        self.result.matrix_world = self.source.matrix_world.copy()
        return self

    def select(self, objects) -> None:
        """Selects only ``objects``; the result is the active object."""
        for obj in self.context.view_layer.objects:
            obj.select_set(obj in objects)
        self.context.view_layer.objects.active = self.result

    def use_cycles(self) -> None:
        scene = self.context.scene
        scene.render.engine = "CYCLES"
        self.cycles = (scene.cycles.device, scene.cycles.samples)
        scene.cycles.device, scene.cycles.samples = "CPU", 1

    def __exit__(self, *exc):
        scene = self.context.scene
        if self.cycles is not None:
            scene.cycles.device, scene.cycles.samples = self.cycles
        scene.render.engine = self.engine
        for modifier, (viewport, render) in self.armatures.items():
            modifier.show_viewport, modifier.show_render = viewport, render
        self.result.matrix_basis = self.matrix
        for obj, (hidden, viewport, unselectable) in self.hidden.items():
            obj.hide_viewport, obj.hide_select = viewport, unselectable
            obj.hide_set(hidden)
        for obj in self.context.view_layer.objects:
            obj.select_set(obj in self.selected)
        self.context.view_layer.objects.active = self.active
        return False


def _run_bake(extrusion: float, max_ray: float, margin: int, size: int, name: str) -> None:
    """Bakes the selected objects' normals into the active object's active image nodes."""
    try:
        bpy.ops.object.bake(type="NORMAL", use_selected_to_active=True, use_cage=False,
                            cage_extrusion=extrusion, max_ray_distance=max_ray, margin=margin,
                            normal_space="TANGENT", target="IMAGE_TEXTURES", save_mode="INTERNAL",
                            use_clear=True, width=size, height=size)
    except RuntimeError as error:
        raise BakeError(f"baking normals onto '{name}' failed: {str(error).strip().splitlines()[-1]}") from None


def _write_png(image, path: str) -> None:
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()


def has_detail(image) -> bool:
    """Whether some texel holds a unit normal more than a degree away from the flat (0, 0, 1): a
    Cycles that cannot bake (Debian's Blender 3.4) leaves none (its texels (0, 0, 1) or zero)."""
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    normals = pixels.reshape(-1, image.channels)[:, :3] * 2.0 - 1.0
    length = np.linalg.norm(normals, axis=1)
    unit = normals[np.abs(length - 1.0) < 0.05] / length[np.abs(length - 1.0) < 0.05, None]
    return bool((unit[:, 2] < np.cos(np.radians(1.0))).any())


def _bake_image(source, result, image, uv_map: str, reach: tuple, margin: int, expect_detail: bool):
    """Bakes into ``image`` with Cycles, or by ray casting when Cycles leaves the map flat though
    the surfaces differ, yielding the fraction done; returns which ("Cycles" or "ray cast")."""
    extrusion, max_ray = reach
    _run_bake(extrusion, max_ray, margin, image.size[0], result.name)
    if not expect_detail or has_detail(image):
        return "Cycles"
    yield 0.0  # Cycles' turn done (nothing to show for it): the rays follow
    yield from bake_raycast.bake_steps(source, result, image, uv_map, extrusion, max_ray, margin)
    if not has_detail(image):
        raise BakeError(f"the bake onto '{result.name}' came back empty: no ray from it reached "
                        f"'{source.name}'")
    return "ray cast"


def save_image(image, folder: str, stem: str, replace: bool = False, kind: str = "normal") -> str:
    """Writes ``image`` as ``<folder>/<stem>_<kind>.png`` atomically and points the image at it;
    returns the path. A file of that name is replaced only with ``replace`` (the batch's own
    output), else the next free name is taken (``_1``, ``_2`` …)."""
    path = os.path.join(folder, f"{stem}_{kind}.png")
    index = 1
    while os.path.exists(path) and not replace:
        path = os.path.join(folder, f"{stem}_{kind}_{index}.png")
        index += 1
    handle, staged = tempfile.mkstemp(prefix=".topstoc-", suffix=".png", dir=folder)
    os.close(handle)
    try:
        _write_png(image, staged)
        os.replace(staged, path)
    except (RuntimeError, OSError) as error:
        if os.path.exists(staged):
            os.remove(staged)
        raise BakeError(f"could not save the normal map {path}: {str(error).strip()}") from None
    image.filepath_raw = path
    return path


def pack_image(image) -> None:
    """Packs the baked pixels into the .blend as PNG (a baked, unsaved image would pack its
    generated colour instead: it is written to a temporary file and packed from there)."""
    handle, staged = tempfile.mkstemp(prefix="topstoc-", suffix=".png")
    os.close(handle)
    try:
        _write_png(image, staged)
        image.pack()
    except RuntimeError as error:
        raise BakeError(f"could not pack the normal map '{image.name}': {str(error).strip()}") from None
    finally:
        os.remove(staged)
    image.filepath_raw = f"//{bpy.path.clean_name(image.name)}.png"  # where Unpack would write it


def bake_folder() -> str:
    """The folder beside the saved .blend; an error for an unsaved file."""
    if not bpy.data.filepath:
        raise BakeError("save the .blend file first to keep normal maps beside it, or choose to pack them")
    return os.path.dirname(bpy.path.abspath(bpy.data.filepath))


def bake_normals(context, source, result, *, size: int = 1024, margin: int = 16, store: str = "PACK",
                 folder: str = None, name: str = None, replace: bool = False, colour: bool = False,
                 progress=None) -> Baked:
    """Bakes ``source``'s shading normals onto ``result`` (its decimated copy) as a tangent-space
    normal map of ``size``² with ``margin`` pixels of bleed. store: "PACK" (into the .blend) or
    "FILE" (``<folder>/<name>_normal.png``; by default beside the .blend, named after the result;
    an existing file replaced only with ``replace``). ``colour``: the base colour too, and every
    other channel the source's materials feed from an image, where the map has a UV map of its own
    (bake_colour.py, bake_channels.py; saved as ``<name>_color.png``, ``<name>_roughness.png`` …). ``progress(fraction)`` follows the bake; its
    False cancels (bake_raycast.Cancelled), leaving ``result`` as it was, like a failed bake."""
    return bake_raycast.drive(bake_normals_steps(context, source, result, size=size, margin=margin, store=store,
                                                 folder=folder, name=name, replace=replace, colour=colour),
                              progress)


def bake_normals_steps(context, source, result, *, size: int = 1024, margin: int = 16, store: str = "PACK",
                       folder: str = None, name: str = None, replace: bool = False, colour: bool = False):
    """bake_normals one step at a time: a generator yielding the fraction done (0 when ready to
    bake, then per chunk of rays), returning the Baked. Closed early (``close()``), or failing, it
    leaves ``result`` and the scene as they were."""
    size = check_size(size)
    check_memory(size, available_memory())
    check_bakeable(source, result)
    context.view_layer.update()  # the world matrices measure_reach reads
    if store == "FILE":
        folder = folder or bake_folder()
    hausdorff_max, diagonal, extrusion, max_ray = measure_reach(source, result)
    old_materials = [slot.material for slot in result.material_slots]
    old_uv = (result.data.uv_layers.active_index, [layer.name for layer in result.data.uv_layers])
    image, made, normals, colour_image, channels = None, [], None, None, {}
    with _SceneState(context, source, result) as state:
        try:
            state.select([result])
            normals = own_normals(result)
            active_uv = result.data.uv_layers.active_index
            uv_map, unwrapped = ensure_uv_map(result, size, margin)
            image = new_image(f"{result.name}_normal", size)
            made = give_materials(result, image, uv_map)
            state.select([source, result])
            state.use_cycles()
            yield 0.0
            # surfaces this close give a flat map rightly (an LOD0 at ratio 1)
            method = yield from _bake_image(source, result, image, uv_map, (extrusion, max_ray), margin,
                                            hausdorff_max > DETAIL * diagonal)
            if colour and unwrapped:
                yield 1.0
                colour_image = _bake_colour(result, made, uv_map, (extrusion, max_ray), margin, size)
                yield from _bake_channels(source, result, made, uv_map, (extrusion, max_ray), margin, size, channels)
            if active_uv >= 0:  # the map made for the bake is not the one the user edits
                result.data.uv_layers.active_index = active_uv
            stem = bpy.path.clean_name(name or result.name)
            path = save_image(image, folder, stem, replace) if store == "FILE" else ""
            colour_path, channel_paths = "", {}
            if colour_image is not None and store == "FILE":
                colour_path = save_image(colour_image, folder, stem, replace, kind="color")
            for kind, baked in channels.items() if store == "FILE" else ():
                channel_paths[kind] = save_image(baked, folder, stem, replace, kind=kind)
            for baked in (image, colour_image, *channels.values()) if store != "FILE" else ():
                if baked is not None:
                    pack_image(baked)
        except (BakeError, bake_raycast.Cancelled, GeneratorExit):
            for baked in (colour_image, *channels.values()):
                if baked is not None:
                    bpy.data.images.remove(baked)
            _undo_materials(result, old_materials, made, image)
            _undo_uv_map(result, *old_uv)
            restore_normals(result, normals)
            raise
    yield 1.0
    return Baked(image, uv_map, unwrapped, hausdorff_max, extrusion, max_ray, method, path, colour_image,
                 colour_path, channels, channel_paths)


def _bake_colour(result, materials, uv_map: str, reach: tuple, margin: int, size: int):
    """The source's base colour baked with Cycles into a new image on ``uv_map`` that
    ``materials`` (the result's copies) read their Base Color from; an error when Cycles bakes none."""
    image = bake_colour.new_colour_image(f"{result.name}_color", size)
    for material in materials:
        bake_colour.wire_colour(material, image, uv_map)
    try:
        bake_colour.run_colour_bake(*reach, margin, size)
    except RuntimeError as error:
        bpy.data.images.remove(image)
        raise BakeError(f"baking the colour onto '{result.name}' failed: {str(error).strip().splitlines()[-1]}") \
            from None
    if bake_colour.is_blank(image):
        bpy.data.images.remove(image)
        raise BakeError(f"this Blender's Cycles baked no colour onto '{result.name}'")
    return image


def _bake_channels(source, result, materials, uv_map: str, reach: tuple, margin: int, size: int, baked: dict):
    """Bakes each channel the source's materials feed from an image (bake_channels.py) into
    ``baked`` ({kind: image}, filled as they come: a failure leaves the done ones to remove)."""
    for channel in bake_channels.textured_channels(source):
        yield 1.0
        try:
            baked[channel[0]] = bake_channels.bake_channel(source, result, materials, channel, uv_map, reach,
                                                           margin, size)
        except RuntimeError as error:
            raise BakeError(f"baking the {channel[0]} onto '{result.name}' failed: "
                            f"{str(error).strip().splitlines()[-1]}") from None


def _undo_materials(result, old_materials, made, image) -> None:
    """Puts the result's materials back after a failed bake and removes what the bake made."""
    for slot, material in zip(result.material_slots, old_materials):
        slot.material = material
    for material in made:
        bpy.data.materials.remove(material)
    if image is not None:
        bpy.data.images.remove(image)


def _undo_uv_map(result, active: int, names: list) -> None:
    """Removes a UV map the bake made and makes the user's active one active again."""
    layers = result.data.uv_layers
    for name in [layer.name for layer in layers if layer.name not in names]:
        layers.remove(layers[name])
    if active >= 0:
        layers.active_index = active


def _scaled(steps, start: float, share: float):
    """Yields what the generator ``steps`` yields mapped onto [start, start + share]; returns its
    value. Closed early, it closes ``steps`` (whose clean-up then runs)."""
    try:
        while True:
            try:
                fraction = next(steps)
            except StopIteration as done:
                return done.value
            yield start + share * fraction
    finally:
        steps.close()


def bake_results_steps(context, settings, pairs):
    """Bakes every (source, result) pair with an operator's BakeParameters, yielding the fraction
    of the whole run done; returns (status lines, one-line failures). A failed bake leaves its
    result as decimated; closed early, the result being baked is left as it was."""
    lines, failures = [], []
    pairs = list(pairs)
    for index, (source, result) in enumerate(pairs):
        steps = bake_normals_steps(context, source, result, size=int(settings.bake_size),
                                   margin=settings.bake_margin, store=settings.bake_store,
                                   colour=settings.bake_colour)
        try:
            baked = yield from _scaled(steps, index / len(pairs), 1 / len(pairs))
        except TopStocError as error:
            failures.append(f"Bake Normals: {error}")
            continue
        where = baked.path or "packed"
        lines.append(f"{result.name}: {baked.image.size[0]}² normal map ({where}, reach {baked.extrusion:.4g})")
    return lines, failures


def remove_results(results) -> None:
    """Removes decimated results with what bakes gave them (material copies holding the map node,
    their images and the files saved for them: fresh names, never a user's file) and their meshes
    when nothing else uses them: a cancelled run leaves nothing."""
    materials = {slot.material for obj in results for slot in obj.material_slots if slot.material is not None
                 and slot.material.node_tree and any(n.label == NODE_LABEL for n in slot.material.node_tree.nodes)}
    images = {node.image for material in materials for node in material.node_tree.nodes
              if node.label in {NODE_LABEL, bake_colour.COLOUR_LABEL, *bake_channels.LABELS} and node.image is not None}
    meshes = {obj.data for obj in results}
    for obj in results:
        bpy.data.objects.remove(obj)
    for mesh in meshes:
        if mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    for material in materials:
        bpy.data.materials.remove(material)
    for image in images:
        path = bpy.path.abspath(image.filepath_raw) if image.packed_file is None else ""
        if path and os.path.isfile(path):
            os.remove(path)
        bpy.data.images.remove(image)
