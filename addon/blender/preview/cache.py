"""Prepared engine meshes, cached per mesh state.

Preparing a mesh (adjacency, normals, importance weights) is the expensive step; each
re-decimation afterwards costs milliseconds. Entries are keyed by the mesh datablock and the
fingerprint of its positions and triangles, so any edit of the geometry misses the cache and
re-prepares: a stale mesh can never be used. The cache holds a few meshes only (they are big).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass, field

from ...core.api.mesh import Mesh
from ..io import mesh_read


@dataclass
class Prepared:
    """A Blender mesh read into arrays and prepared for the engine."""

    arrays: mesh_read.MeshArrays
    mesh: Mesh
    digest: str
    #: the live preview's seconds of its latest chosen-settings result, per options (session.py)
    final_seconds: dict = field(default_factory=dict)


class PreparedCache:
    """Least-recently-used cache of prepared meshes; ``prepare`` may run on any thread (the live
    preview prepares on a worker), the bookkeeping is locked."""

    def __init__(self, capacity: int = 2):
        self.capacity = capacity
        self._entries: OrderedDict = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def get(self, mesh_data) -> Prepared:
        """The prepared form of a bpy Mesh, re-prepared when its geometry changed (main thread)."""
        return self.prepare(mesh_data.name_full, mesh_read.read_mesh(mesh_data))

    def prepare(self, name: str, arrays: mesh_read.MeshArrays, progress=None) -> Prepared:
        """The preparation of ``arrays`` read from the mesh datablock ``name`` (its ``name_full``):
        cached, or made now (any thread; reads no Blender data). ``progress`` is handed to
        :class:`Mesh` (its False cancels with ``Cancelled``; nothing is cached then)."""
        digest = arrays.digest()
        key = (name, digest)
        with self._lock:
            entry = self._entries.get(key)
            if entry is not None:
                self._entries.move_to_end(key)
                self.hits += 1
                entry.arrays = arrays  # same geometry; loop/polygon maps refreshed all the same
                return entry
            self.misses += 1
        entry = Prepared(arrays, Mesh(arrays.vertices, arrays.triangles, progress=progress), digest)
        with self._lock:
            self._entries[key] = entry
            while len(self._entries) > self.capacity:
                self._entries.popitem(last=False)
        return entry

    def clear(self) -> None:
        with self._lock:
            self._entries.clear()

    def clear_kept(self) -> None:
        """Frees what the cached meshes keep for later decimations (flood caches, collapse states),
        keeping their preparations: the next decimation of each starts cold."""
        with self._lock:
            entries = list(self._entries.values())
        for entry in entries:
            entry.mesh.clear_floods()


#: The add-on's cache (cleared on unregister and when a file is loaded).
prepared_meshes = PreparedCache()
