"""Live preview: re-decimates the cached prepared mesh while the user drags, off the main thread.

A PreviewSession owns a temporary object that shows the current result (geometry only, no
attributes: the final result is written with every attribute when the user applies). Engine
calls release the GIL, so the interface stays responsive even when one update is slow; the
session always computes the most recent request and drops the ones in between. The worker
goes on to the latest request as soon as it finishes one, without waiting for the main thread
to notice (the modal timer) or to write the result: the rate a user sees is then set by the
decimation alone whenever the write is the shorter of the two.
"""

from __future__ import annotations

import threading
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
        self._lock = threading.Lock()
        self._future: Optional[Future] = None  # the worker loop, while it runs
        self._pending: Optional[float] = None  # latest ratio asked for and not yet started
        self._started: Optional[float] = None  # ratio of the newest computation started
        self._finished = None                  # newest computed result not shown yet
        self._error: Optional[BaseException] = None  # raised by the worker, re-raised by poll
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
        with self._lock:
            self._started = ratio

    def request(self, ratio: float) -> None:
        """Asks for ``ratio``; only the latest request is computed."""
        with self._lock:
            self._pending = ratio
        self._start_worker()

    def _start_worker(self) -> None:
        with self._lock:
            if self._future is None and self._pending is not None and self._pending != self._started:
                self._future = self._pool.submit(self._work)

    def _work(self) -> None:
        """Worker loop: computes the latest pending request until none is new."""
        while True:
            with self._lock:
                ratio, self._pending = self._pending, None
                if ratio is None or ratio == self._started:
                    self._future = None
                    return
                self._started = ratio
            try:
                finished = self.compute(ratio)
            except Exception as error:  # noqa: BLE001 - handed to the main thread
                with self._lock:
                    self._error, self._future, self._started = error, None, None
                return
            with self._lock:
                self._finished = finished  # a newer result replaces one not shown yet

    def poll(self) -> bool:
        """Shows the newest finished result (main thread); True when the view changed.

        The worker is already computing the next request meanwhile, if there is one."""
        with self._lock:
            finished, self._finished = self._finished, None
            error, self._error = self._error, None
        if error is not None:
            raise error  # engine errors surface on the main thread
        self._start_worker()  # a request that came while the worker was stopping
        if finished:
            self.show(*finished)
        return finished is not None

    @property
    def busy(self) -> bool:
        with self._lock:
            return self._future is not None or self._finished is not None

    def close(self) -> None:
        """Removes the preview object and shows the original again."""
        with self._lock:
            self._pending = None  # the worker stops after its current computation
        self._pool.shutdown(wait=True)
        bpy.data.objects.remove(self.preview)
        bpy.data.meshes.remove(self.mesh)
        self.obj.hide_set(self.was_hidden)
