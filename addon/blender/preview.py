"""Live preview: re-decimates the cached prepared mesh while the user drags, off the main thread.

A PreviewSession owns a temporary object that shows the current result (geometry only, no
attributes: the final result is written with every attribute when the user applies). Engine
calls release the GIL, so the interface stays responsive even when one update is slow; the
session always computes the most recent request and drops the ones in between.
"""

from __future__ import annotations

import time
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Optional

import bpy

from ..core.mesh_edges import mesh_edges
from . import mesh_io, pipeline
from .guidance import gather

PREVIEW_SUFFIX = "_TopStocPreview"


class PreviewSession:
    """Preview of one object's decimation at a changing ratio."""

    def __init__(self, context, obj, params, region_3d=None):
        self.obj = obj
        self.prepared = pipeline.prepare(obj)
        self.guidance = gather(obj, self.prepared.arrays, context.scene, None, region_3d)
        self.prepared.mesh.feature_layout(self.guidance.regions, self.guidance.borders)
        self.options = pipeline.options_kwargs(params)
        self.mesh = bpy.data.meshes.new(obj.name + PREVIEW_SUFFIX)
        for material in obj.data.materials:
            self.mesh.materials.append(material)
        self.preview = bpy.data.objects.new(obj.name + PREVIEW_SUFFIX, self.mesh)
        for collection in obj.users_collection or (context.scene.collection,):
            collection.objects.link(self.preview)
        self.preview.matrix_world = obj.matrix_world.copy()
        self.was_hidden = obj.hide_get()
        obj.hide_set(True)
        self._pool = ThreadPoolExecutor(max_workers=1)
        self._future: Optional[Future] = None
        self._pending: Optional[float] = None
        self.ratio: Optional[float] = None
        self.result = None
        self.seconds_decimate = 0.0
        self.seconds_write = 0.0

    def compute(self, ratio: float):
        """Decimates at ``ratio`` and derives the result's edges (any thread: the main thread
        then only copies arrays into the preview mesh)."""
        start = time.perf_counter()
        result = self.prepared.mesh.decimate(ratio=ratio, **self.options, **self.guidance.decimate_kwargs())
        edges = mesh_edges(result.triangles, len(result.vertices))
        return ratio, result, edges, time.perf_counter() - start

    def show(self, ratio: float, result, edges, seconds: float) -> None:
        """Puts a result into the preview object (main thread)."""
        start = time.perf_counter()
        mesh_io.fill_geometry(self.mesh, result.vertices, result.triangles, edges)
        self.ratio, self.result, self.seconds_decimate = ratio, result, seconds
        self.seconds_write = time.perf_counter() - start

    def update(self, ratio: float) -> None:
        """Synchronous update (benchmarks, tests)."""
        self.show(*self.compute(ratio))

    def request(self, ratio: float) -> None:
        """Asks for ``ratio``; only the latest request is computed."""
        self._pending = ratio

    def poll(self) -> bool:
        """Starts the next request, then shows a finished result; True when the view changed.

        The next decimation starts before the finished one is written, so that the worker
        computes while the main thread fills the preview mesh."""
        finished = None
        if self._future is not None and self._future.done():
            finished, self._future = self._future.result(), None  # re-raises engine errors here
        latest = finished[0] if finished else self.ratio
        if self._future is None and self._pending is not None and self._pending != latest:
            self._future = self._pool.submit(self.compute, self._pending)
            self._pending = None
        if finished:
            self.show(*finished)
        return finished is not None

    @property
    def busy(self) -> bool:
        return self._future is not None

    def close(self) -> None:
        """Removes the preview object and shows the original again."""
        if self._future is not None:
            self._future.cancel()
        self._pool.shutdown(wait=True)
        bpy.data.objects.remove(self.preview)
        bpy.data.meshes.remove(self.mesh)
        self.obj.hide_set(self.was_hidden)
