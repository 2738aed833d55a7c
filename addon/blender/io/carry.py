"""What follows the source object onto a decimated result: shape keys, modifiers, parent,
collections and custom properties (vertex groups and mesh attributes: see mesh_attributes and mesh_write).

Shape keys: the result has every key of the source with its name, value, slider range, mute
flag, interpolation, vertex group and relative key. A key's position at output vertex ``i`` is
the output position plus the key's offset (key minus mesh position) at the place it stands for:

    key_out[i] = position_out[i] + (key_in[kept[i]] - position_in[kept[i]])   (did not move)
    key_out[i] = position_out[i] + sum_j w_j (key_in[t_j] - position_in[t_j])  (moved)

A vertex that did not move is the input vertex ``kept[i]``, so every key equals the source's key
there exactly. A vertex the quality mode moved (filtered placement, quadric collapses) takes each
key's offset interpolated at its place on the basis: ``t`` is the input triangle its attributes
come from and ``w`` its barycentric weights there (topstoc.core.carry.attributes.moved_vertices, the
same as for UVs and colours), so the morph follows the surface the vertex now stands on.
Vertex-group weights (the rig's skin) are mixed at the same place (pipeline.skin_weights).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import bpy
import numpy as np

from ...core.carry.attributes import MovedVertices, point_values
from . import dna_arrays

KEY_SETTINGS = ("value", "slider_min", "slider_max", "mute", "interpolation", "vertex_group")


@dataclass
class ShapeKeys:
    """The shape keys of a mesh, read before its mesh is replaced."""

    use_relative: bool = True
    reference: str = ""
    names: list = field(default_factory=list)
    coordinates: list = field(default_factory=list)   #: (n, 3) float64 per key
    settings: list = field(default_factory=list)      #: {setting: value} per key
    relative_to: list = field(default_factory=list)   #: name of each key's relative key


def read_shape_keys(mesh: bpy.types.Mesh) -> ShapeKeys:
    keys = ShapeKeys()
    if mesh.shape_keys is None:
        return keys
    key = mesh.shape_keys
    keys.use_relative = key.use_relative
    keys.reference = key.reference_key.name
    n = len(mesh.vertices)
    for block in key.key_blocks:
        co = dna_arrays.shape_key_positions(block) if len(block.data) == n else None
        if co is None:
            co = np.empty(3 * n, dtype=np.float32)
            if n:
                block.data.foreach_get("co", co)
        keys.names.append(block.name)
        keys.coordinates.append(co.reshape(n, 3).astype(np.float64))
        keys.settings.append({name: getattr(block, name) for name in KEY_SETTINGS})
        keys.relative_to.append(block.relative_key.name)
    return keys


def write_shape_keys(obj: bpy.types.Object, keys: ShapeKeys, source_positions: np.ndarray,
                     output_positions: np.ndarray, kept: np.ndarray, moved: MovedVertices = None,
                     source_triangles: np.ndarray = None) -> None:
    """Adds ``keys`` to ``obj``'s mesh (which has none yet), following the output vertices;
    ``moved`` (with the source's triangles) says where moved vertices take their offsets from."""
    if not keys.names:
        return
    kept = np.asarray(kept, dtype=np.int64)
    output_positions = np.asarray(output_positions, dtype=np.float64)
    shift = output_positions - source_positions[kept]  # zero where the vertex did not move
    at = moved.moved if moved is not None else np.zeros(0, dtype=np.int64)
    blocks = []
    for name, co, settings in zip(keys.names, keys.coordinates, keys.settings):
        block = obj.shape_key_add(name=name, from_mix=False)
        values = co[kept] + shift
        if len(at):
            offsets = point_values(co - source_positions, kept, moved, source_triangles)
            values[at] = output_positions[at] + offsets[at]
        if len(values):
            block.data.foreach_set("co", np.ascontiguousarray(values, dtype=np.float32).ravel())
        blocks.append(block)
    for block, settings, relative in zip(blocks, keys.settings, keys.relative_to):
        # slider range before the value: the value is clamped to the range
        block.slider_min, block.slider_max = settings["slider_min"], settings["slider_max"]
        for name in KEY_SETTINGS:
            setattr(block, name, settings[name])
        block.relative_key = obj.data.shape_keys.key_blocks.get(relative, block)
    obj.data.shape_keys.use_relative = keys.use_relative


def copy_modifiers(source: bpy.types.Object, target: bpy.types.Object) -> None:
    """Copies the modifier stack: every writable setting, pointers kept (an Armature modifier
    stays bound to the same armature object; the vertex groups carry the weights)."""
    for modifier in source.modifiers:
        copy = target.modifiers.new(modifier.name, modifier.type)
        for prop in modifier.bl_rna.properties:
            name = prop.identifier
            if prop.is_readonly or name in ("name", "type"):
                continue
            try:
                setattr(copy, name, getattr(modifier, name))
            except (AttributeError, TypeError, ValueError):
                pass  # settings that depend on data the copy does not have yet
        if modifier.type != "NODES":
            continue
        for key in modifier.keys():  # geometry-nodes inputs live in ID properties
            try:
                copy[key] = modifier[key]
            except (TypeError, ValueError):
                pass


def copy_custom_properties(source, target) -> None:
    """The source's own custom properties (the add-on's settings are left out)."""
    for key in source.keys():
        if key.startswith("topstoc") or key.startswith("_RNA_UI") or key in target.keys():
            continue
        try:
            target[key] = source[key]
        except (TypeError, ValueError):
            pass


def link_like(source: bpy.types.Object, target: bpy.types.Object, scene) -> None:
    """Puts ``target`` in the source's collections, under its parent, at its transform."""
    for collection in source.users_collection or (scene.collection,):
        collection.objects.link(target)
    target.parent = source.parent
    target.parent_type = source.parent_type
    if source.parent_type == "BONE":
        target.parent_bone = source.parent_bone
    target.matrix_parent_inverse = source.matrix_parent_inverse.copy()
    target.matrix_world = source.matrix_world.copy()


def is_rigged(obj: bpy.types.Object) -> bool:
    """True when moving the object away from its rig would change how it deforms."""
    return (any(m.type == "ARMATURE" for m in obj.modifiers)
            or (obj.parent is not None and obj.parent_type in {"ARMATURE", "BONE"}))


def place_beside(source: bpy.types.Object, target: bpy.types.Object) -> str:
    """A new result goes beside the original, offset along X by the original's bounding-box
    width; a rigged original is hidden instead (moving the copy off its rig would change its
    deformation). Returns "BESIDE" or "HIDDEN"."""
    if is_rigged(source):
        source.hide_set(True)
        return "HIDDEN"
    xs = [(source.matrix_world @ _vector(corner)).x for corner in source.bound_box]
    width = max(xs) - min(xs)
    matrix = target.matrix_world.copy()
    matrix.translation.x += 1.1 * width if width > 0 else 1.0
    target.matrix_world = matrix
    return "BESIDE"


def _vector(values):
    from mathutils import Vector
    return Vector(values)
