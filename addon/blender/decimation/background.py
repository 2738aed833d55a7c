"""Decimations of several objects on a worker thread, so that a long one leaves the window live.

The main thread reads every object first (``pipeline.read_input``: Blender data can only be
read there) and writes the results at the end; the worker prepares and decimates, saying how far
it got, and finds where moved vertices take their attributes from (numpy and engine work the
write would otherwise do on the main thread). ``cancel`` stops the engine at its next step,
whether it prepares a mesh, decimates it or searches an error target (a mirrored decimation runs
to its end, unseen). Nothing in the scene changes before the caller writes, so a cancelled job
leaves every object as it was.
"""

from __future__ import annotations

import threading
import time

from ...core.api.decimate import CancelFlag
from ...core.api.loops import Cancelled
from ...core.carry.attributes import moved_vertices_of
from ...core.support.errors import TopStocError
from . import pipeline

THREAD_NAME = "topstoc-decimate"


class BackgroundDecimation:
    """Decimates each ``pipeline.Input`` in turn on a worker thread (started at once, or by
    ``begin`` when ``deferred``)."""

    def __init__(self, reads: list, deferred: bool = False):
        self.reads = reads
        self.outcomes = []  # (Run, None) or (None, one-line failure) per read finished, in order
        self.error = None   # an unexpected exception of the worker, raised by ``finished``
        self.started = time.perf_counter()
        self._cancel = threading.Event()
        self._stop_engine = CancelFlag()  # set with _cancel: stops a decimation already running
        self._lock = threading.Lock()
        self._state = (0, 0.0, "preparing")  # object index, fraction of its preparation, what runs
        self._thread = threading.Thread(target=self._work, name=THREAD_NAME, daemon=True)
        if not deferred:
            self.begin()

    def begin(self) -> None:
        """Starts the worker (once). An operator's invoke defers it to its first modal event:
        Blender 3.4 crashes when a Python thread runs while an operator called through bpy.ops
        with a context override is still in Blender's C code (preview/session.py's begin)."""
        if self._thread.ident is None:
            self.started = time.perf_counter()
            self._thread.start()

    def _work(self) -> None:
        for index, read in enumerate(self.reads):
            try:
                run = pipeline.decimate_read(read, self._preparing(index), self._searching(index), self._stop_engine,
                                             one_shot=True)
                self._state = (index, 1.0, "finding the sources of moved vertices")
                # not at the write; from the prepared mesh: the arrays handed over stay there
                run.moved = moved_vertices_of(run.prepared.mesh, run.result)
                outcome = (run, None)
            except Cancelled:
                return
            except TopStocError as failure:
                outcome = (None, str(failure))
            except BaseException as error:  # noqa: BLE001 - handed to the main thread
                self.error = error
                return
            with self._lock:
                self.outcomes.append(outcome)

    def _preparing(self, index: int):
        """The preparation's progress callback for object ``index`` (False cancels it)."""
        def told(fraction: float, stage: str) -> bool:
            self._state = (index, fraction, f"preparing: {stage}" if fraction < 1.0 else "decimating")
            return not self._cancel.is_set()
        return told

    def _searching(self, index: int):
        """An error target's progress callback, one call per probe (False cancels the search)."""
        def told(probe: int, _target: int, vertices: int, error: float, passed: bool) -> bool:
            verdict = "within" if passed else "over"
            self._state = (index, 1.0, f"max deviation: probe {probe}, {vertices:,} vertices, {verdict} the bound")
            return not self._cancel.is_set()
        return told

    def cancel(self) -> None:
        """Stops the worker at the engine's next step (a preparation's, a decimation's or an error
        search's); what it finishes after is dropped."""
        self._cancel.set()
        self._stop_engine.set()

    @property
    def cancelled(self) -> bool:
        return self._cancel.is_set()

    def finished(self) -> bool:
        """True once every object is done (or the job stopped); raises the worker's unexpected error."""
        if self._thread.ident is None or self._thread.is_alive():
            return False
        if self.error is not None:
            raise self.error
        return True

    def wait(self, timeout: float = None) -> bool:
        """Blocks until the worker ends (tests, scripts); ``finished`` then."""
        self._thread.join(timeout)
        return self.finished()

    def progress(self) -> tuple:
        """(fraction of the whole job, 0-1; a line saying what runs and how long it has run). A
        preparation counts for half an object (the decimation has no progress of its own)."""
        index, fraction, doing = self._state
        with self._lock:
            finished = len(self.outcomes)
        if finished > index:  # the next object has not reported yet
            index, fraction, doing = finished, 0.0, "starting"
        done = min(1.0, (index + 0.5 * fraction) / max(1, len(self.reads)))
        if index < len(self.reads):
            read = self.reads[index]
            what = f"'{read.obj.name}' ({read.arrays.num_triangles:,} triangles, {index + 1} of {len(self.reads)}): " \
                   f"{doing}"
        else:
            what = "writing the results"
        return done, f"{what}  {time.perf_counter() - self.started:.1f} s"
