"""Which meshes changed since their results were computed (runtime state, never saved).

A depsgraph handler bumps a per-object *geometry epoch* whenever Blender reports a geometry
update of the object or its mesh (edits, undo, modifiers of the data). Consumers compare
epochs to know when to re-read positions, and ``connectivity_stamp`` memoises the
fingerprint of the mesh's connectivity per epoch, so the panels and overlays can tell
cheaply whether stored topology results still describe the mesh. Positions are not part of
that fingerprint: moving vertices changes no invariant and no loop's vertex ids.
"""

from __future__ import annotations

import hashlib
from collections import defaultdict

import bpy
import numpy as np
from bpy.app.handlers import persistent

from ..io import mesh_access, mesh_read

_epochs: dict = defaultdict(int)
_stamps: dict = {}  # object name -> (epoch, mesh name, stamp)


def epoch(obj) -> int:
    """The geometry epoch of ``obj`` (changes whenever its mesh changed)."""
    return _epochs[obj.name_full]


def bump(obj) -> None:
    """Marks ``obj``'s geometry as changed (the add-on's own edits call this too)."""
    _epochs[obj.name_full] += 1


def connectivity_stamp(mesh: bpy.types.Mesh) -> str:
    """Fingerprint of the mesh's vertex count, edges and polygons (not its positions)."""
    h = hashlib.blake2b(digest_size=16)
    h.update(np.array([len(mesh.vertices), len(mesh.edges), len(mesh.polygons)], dtype=np.int64).data)
    h.update(mesh_access.read_indices(mesh.edges, "vertices", len(mesh.edges), 2).data)
    h.update(mesh_access.read_indices(mesh.polygons, "loop_start", len(mesh.polygons)).data)
    h.update(mesh_read.corner_vertices(mesh).data)
    return h.hexdigest()


def current_stamp(obj) -> str:
    """``connectivity_stamp`` of ``obj``'s mesh, recomputed only when its epoch changed.

    In Edit Mode the mesh data is the state of the last mode switch (Blender syncs it then).
    """
    key = obj.name_full
    memo = _stamps.get(key)
    if memo is not None and memo[0] == _epochs[key] and memo[1] == obj.data.name_full:
        return memo[2]
    stamp = connectivity_stamp(obj.data)
    _stamps[key] = (_epochs[key], obj.data.name_full, stamp)
    return stamp


def forget(obj=None) -> None:
    """Drops the memoised stamps (of one object, or all)."""
    if obj is None:
        _stamps.clear()
        _epochs.clear()
    else:
        _stamps.pop(obj.name_full, None)
        _epochs[obj.name_full] += 1


@persistent
def _on_depsgraph_update(scene, depsgraph):
    meshes = set()
    for update in depsgraph.updates:
        datablock = update.id
        if isinstance(datablock, bpy.types.Object) and update.is_updated_geometry:
            _epochs[datablock.original.name_full] += 1
        elif isinstance(datablock, bpy.types.Mesh):
            meshes.add(datablock.original.name_full)
    if meshes:
        for obj in bpy.data.objects:
            if obj.type == "MESH" and obj.data is not None and obj.data.name_full in meshes:
                _epochs[obj.name_full] += 1


@persistent
def _on_reset(*_args):
    """After undo, redo or loading a file every object may have changed."""
    for key in list(_epochs):
        _epochs[key] += 1
    _stamps.clear()


HANDLERS = (("depsgraph_update_post", _on_depsgraph_update), ("undo_post", _on_reset),
            ("redo_post", _on_reset), ("load_post", _on_reset))


def register():
    for name, function in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if function not in handlers:
            handlers.append(function)


def unregister():
    for name, function in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if function in handlers:
            handlers.remove(function)
    forget()
