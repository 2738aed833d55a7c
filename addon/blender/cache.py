"""Prepared engine meshes, cached per mesh state.

Preparing a mesh (adjacency, normals, importance weights) is the expensive step; each
re-decimation afterwards costs milliseconds. Entries are keyed by the mesh datablock and the
fingerprint of its positions and triangles, so any edit of the geometry misses the cache and
re-prepares: a stale mesh can never be used. The cache holds a few meshes only (they are big).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

from ..core.mesh import Mesh
from . import mesh_io


@dataclass
class Prepared:
    """A Blender mesh read into arrays and prepared for the engine."""

    arrays: mesh_io.MeshArrays
    mesh: Mesh
    digest: str


class PreparedCache:
    """Least-recently-used cache of prepared meshes."""

    def __init__(self, capacity: int = 2):
        self.capacity = capacity
        self._entries: OrderedDict = OrderedDict()
        self.hits = 0
        self.misses = 0

    def get(self, mesh_data) -> Prepared:
        """The prepared form of a bpy Mesh, re-prepared when its geometry changed."""
        arrays = mesh_io.read_mesh(mesh_data)
        digest = arrays.digest()
        key = (mesh_data.name_full, digest)
        entry = self._entries.get(key)
        if entry is not None:
            self._entries.move_to_end(key)
            self.hits += 1
            entry.arrays = arrays  # same geometry; loop/polygon maps refreshed all the same
            return entry
        self.misses += 1
        entry = Prepared(arrays, Mesh(arrays.vertices, arrays.triangles), digest)
        self._entries[key] = entry
        while len(self._entries) > self.capacity:
            self._entries.popitem(last=False)
        return entry

    def find(self, mesh_data):
        """(arrays, digest, entry or None): the mesh read now and its cached preparation, if any
        (the live preview prepares a miss on a worker thread and hands it to ``add``)."""
        arrays = mesh_io.read_mesh(mesh_data)
        digest = arrays.digest()
        return arrays, digest, self._entries.get((mesh_data.name_full, digest))

    def add(self, mesh_data, arrays, digest: str, mesh: Mesh) -> Prepared:
        """Stores a preparation made elsewhere (same rules as ``get``)."""
        entry = Prepared(arrays, mesh, digest)
        self._entries[(mesh_data.name_full, digest)] = entry
        while len(self._entries) > self.capacity:
            self._entries.popitem(last=False)
        return entry

    def clear(self) -> None:
        self._entries.clear()


#: The add-on's cache (cleared on unregister and when a file is loaded).
prepared_meshes = PreparedCache()
