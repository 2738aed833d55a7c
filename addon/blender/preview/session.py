"""Live preview: re-decimates the cached prepared mesh while the user drags, off the main thread.

Starting is immediate: creating a PreviewSession reads the mesh arrays and hands them to a
worker, then reads the guidance sources (Blender data can only be read on the main thread) and
returns. The worker fingerprints the arrays, prepares the mesh when the cache does not hold it
(reporting its progress, which the operator shows; ``close`` cancels the preparation in the
engine, not only the wait), turns the guidance read into engine arguments (UV seams, material
regions: numpy work that takes seconds on big UV-mapped meshes) and decimates the first request. Nothing in the scene changes before the first result: the preview
object is made, and the original hidden, when ``poll`` shows it.

A PreviewSession owns a temporary object that shows the current result (geometry only, no
attributes: the final result is written with every attribute when the user applies). Engine
calls release the GIL, so the interface stays responsive even when one update is slow; the
session always computes the most recent request and drops the ones in between. A worker goes
on to the latest request as soon as it finishes one, without waiting for the main thread to
notice (the modal timer) or to write the result.

Two workers run when the machine has two cores or more: while one decimates, the next request
starts on the other, and the engine gives each call its share of the free cores. A decimation
is bound by memory latency more than by arithmetic, so two running side by side on one thread
each show more updates per second than one using both threads (docs/benchmarks.md). Results
are shown in the order they were requested: one that finishes after a newer one was shown is
dropped.

While the user drags, the preview shows drafts of the fast mode (plain TopStoc, milliseconds):
the geometry without the attribute sources and without the engine's final output check (its
partition checks and repairs still run; core.api.decimate's ``draft``). When no new ratio has
been asked for REST_SECONDS, the drag rests: the same ratio is computed in full with the chosen
settings on a free worker (the draft still running is not waited for), checked, and replaces
the draft when it is ready (the paint means the same in both modes, so the density does not
jump); Enter writes only such a result. A draft takes about three quarters of the full fast
decimation's time. Where the chosen settings' result took at most DIRECT_SECONDS (measured on
this mesh, in this session or an earlier one), the drag asks for it directly: the draft is
the result itself. The chosen settings' recent results are kept per ratio, so going back to a
ratio shows its result at once.

Where that result is slow, a worker with no draft to compute starts it for the latest ratio
when the drag pauses (SPECULATE, SPECULATE_AFTER: shorter than a rest, longer than between two
mouse events, so that a sweep keeps both workers for drafts). The ratio moving on cancels it in
the engine; when the drag rests there it is already under way (the rest takes it over instead
of starting anew) or done (it is shown as soon as it is, rest or not). One such computation
runs at a time, so a worker stays free for the drafts.

Before that, from the start of the preview and all along the drag, a worker with nothing else to
do warms the chosen settings' computation up (warm_up.py): it builds what the rested result
resumes from, toward a little above the highest ratio asked, so that the rest runs only the
part that depends on its ratio.
"""

from __future__ import annotations

import os
import threading
import time
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from typing import Optional

import bpy
import numpy as np

from ...core.carry.attributes import moved_vertices
from ...core.api.loops import Cancelled
from ...core.api.decimate import CancelFlag, warm_up
from ...core.api.mesh_edges import mesh_edges
from ..io import mesh_read, mesh_write, edge_flags
from ..decimation import pipeline
from ..decimation.guidance import read as read_guidance
from .warm_up import WarmUps

PREVIEW_SUFFIX = "_TopStocPreview"
WORKERS = 2 if (os.cpu_count() or 1) >= 2 else 1
REST_SECONDS = 0.08  # no new ratio asked this long: the drag rests (several mouse events would have come)
DIRECT_SECONDS = 0.12  # a chosen-settings result this fast is what the drag shows, instead of drafts
KEPT_RESULTS = 8  # chosen-settings results kept per ratio
SPECULATE = True  # a worker with no draft to compute starts the latest ratio's chosen-settings result
SPECULATE_AFTER = 0.02  # ... once no new ratio came this long (a pause of the hand, not between two events),
                        # or twice the drag's recent interval between ratios when that is longer
EVENT_GAP = 0.1  # ratios asked closer than this are one drag's events (their interval is averaged)
THREAD_PREFIX = "topstoc-preview"


class PreviewSession:
    """Preview of one object's decimation at a changing ratio.

    ratio: the first request (computed as soon as the mesh is prepared); without it nothing is
    computed until ``request`` or ``update``.
    """

    def __init__(self, context, obj, panel, region_3d=None, ratio: Optional[float] = None,
                 deferred: bool = False):
        pipeline.check_decimatable(obj)
        self.obj = obj
        arrays = mesh_read.read_mesh(obj.data)  # the main thread's work: Blender data
        self._edge_flags = edge_flags.read_carried_edge_flags(obj.data)  # seams, sharp edges the preview shows
        self.num_triangles = len(arrays.triangles)
        self.guidance = None                   # made by the worker from what is read below
        self._read_guidance = None             # the rules to run on it (guidance.read)
        self._guidance_read = threading.Event()
        self.options = pipeline.decimate_options(panel)
        self.settings = pipeline.settings_of(panel)  # what an applied result remembers (Regenerate)
        # While dragging: drafts of the fast mode, unmirrored; at rest: the chosen settings, in full.
        self.drag_options = dict(self.options, mode="fast", placement=None, refine=None, draft=True, symmetry=None)
        self.prepared = None                   # set by the worker once the mesh is prepared
        self.mesh = self.preview = None        # made when the first result is shown
        self.was_hidden = obj.hide_get()
        self._lock = threading.Lock()
        self._ready = threading.Event()        # preparation finished (or failed)
        self._cancel = threading.Event()       # close() asks the preparation to stop
        self._progress = (0.0, "fingerprint")  # preparation: fraction done and current step
        self._workers = 1                      # worker loops running (the start job counts)
        self._pending = self.key(ratio, False) if ratio is not None else None  # latest request not started
        self._asked = self._pending            # latest request, and when it came (rest detection)
        self._asked_at = time.perf_counter()
        self._highest = ratio or 0.0           # the highest ratio asked (what the warm-ups serve)
        self._interval = 0.0                   # running average of the seconds between a drag's ratios
        self._new_request = threading.Event()  # wakes a worker waiting to speculate
        self._waiting = 0                      # workers waiting so (not staggered against: idle)
        self._kept = OrderedDict()             # ratio -> finished chosen-settings computation (KEPT_RESULTS)
        self._speculation = None               # (key, CancelFlag) of the chosen-settings computation
                                               # started ahead of the rest (SPECULATE), while it runs
        self._options_key = repr(sorted(self.options.items()))  # the prepared mesh's final_seconds key
        self.warm_ups = WarmUps(self._warm_up)  # what the rests resume from, built by idle workers
        self._started: Optional[tuple] = None  # newest computation started
        self._started_count = 0                # computations started (their order numbers)
        self._shown_order = 0                  # order number of the result shown last
        self._finished = None                  # (order, result) newest computed, not shown yet
        self._error: Optional[BaseException] = None  # raised by a worker, re-raised by poll
        self._last_start = 0.0                 # when the newest computation started
        self._typical = 0.0                    # running average of a computation's seconds
        self.ratio: Optional[float] = None
        self.final = False                     # the shown result has the chosen settings
        self._applying = None                  # key of the result Enter asked for, until it is written
        self._to_apply = None                  # (ratio, result, seconds) of it, once computed
        self._sources = None                   # (result, MovedVertices or None while found) of the newest
                                               # chosen-settings result: the write's numpy part, on a worker
        self.apply_started = None              # when Enter asked for it
        self.final_seconds = None              # seconds of the latest computation with the chosen settings
        self.result = None
        self.seconds_decimate = 0.0
        self.seconds_write = 0.0
        self._pool = ThreadPoolExecutor(max_workers=WORKERS, thread_name_prefix=THREAD_PREFIX)
        self.start = None                      # the start job (a Future), once begun
        self._start_args = (obj.name, obj.data.name_full, arrays)
        if not deferred:
            self.begin()
        try:  # Blender data only; turning it into engine arguments is the worker's
            self._read_guidance = read_guidance(obj, arrays, context.scene, None, region_3d)
        except BaseException:
            self.close()  # stops the preparation just started
            raise
        finally:
            self._guidance_read.set()

    # -- starting (worker) ----------------------------------------------------------------

    def begin(self) -> None:
        """Starts the worker that prepares the mesh (once). An operator's invoke makes the session
        ``deferred`` and begins it at its first modal event: Blender 3.4 crashes (a dict read
        without the GIL in its context lookup) when a Python thread runs while the operator
        called through bpy.ops with a context override is still in Blender's C code."""
        if self.start is None and not self._cancel.is_set():
            self.start = self._pool.submit(self._start, *self._start_args)
            self._start_args = None

    def _report(self, fraction: float, stage: str) -> bool:
        """The engine's progress callback during preparation; False stops it (Cancelled)."""
        self._progress = (fraction, stage)
        return not self._cancel.is_set()

    def _start(self, obj_name: str, mesh_name: str, arrays) -> None:
        """Prepares (or finds) the mesh, then works on the requests like any worker."""
        try:
            prepared = pipeline.prepare_arrays(obj_name, mesh_name, arrays, self._report)
            self._guidance_read.wait()
            if self._read_guidance is None:  # reading it failed: the session is closed
                raise Cancelled("cancelled: the guidance could not be read")
            self.guidance = self._read_guidance()
            prepared.mesh.feature_layout(self.guidance.regions, self.guidance.borders)  # shared by the workers
        except BaseException as error:  # noqa: BLE001 - handed to the main thread (Cancelled too)
            with self._lock:
                self._error, self._workers = error, self._workers - 1
            self._ready.set()
            raise
        with self._lock:
            self.prepared = prepared
            self.final_seconds = prepared.final_seconds.get(self._options_key)  # an earlier session's
            if self._pending is not None and self.direct:  # the first request, fast enough in full
                self._pending = self._asked = self.key(self._pending[0], True)
        self._ready.set()
        self._work()

    @property
    def preparing(self) -> bool:
        """True until the mesh is prepared (or its preparation failed)."""
        return not self._ready.is_set()

    def progress(self) -> tuple:
        """(fraction done, step name) of the preparation."""
        return self._progress

    def wait_prepared(self, timeout: float = None) -> None:
        """Blocks until the mesh is prepared; raises the preparation's error."""
        self._ready.wait(timeout)
        with self._lock:
            error = self._error if self.prepared is None else None
            if error is not None:
                self._error = None
        if error is not None:
            raise error

    # -- decimating ---------------------------------------------------------------------------

    def key(self, ratio: float, final: bool) -> tuple:
        """A request's key: (ratio, made in full with the chosen settings)."""
        return ratio, bool(final)

    def compute(self, ratio: float, final: bool = False, cancel: Optional[CancelFlag] = None):
        """Decimates at ``ratio`` (fast, or with the chosen settings with ``final``) and derives the
        result's edges (any thread: the main thread then only copies arrays into the preview);
        ``cancel`` set stops the engine (Cancelled)."""
        start = time.perf_counter()
        options = self.options if final else self.drag_options
        mesh = self.prepared.mesh
        if final:
            self.warm_ups.settle(ratio, cancel)
        job = pipeline.engine_job(mesh, {"ratio": ratio}, options, self.guidance)
        result = pipeline.run_engine(mesh, job) if cancel is None else pipeline.run_engine(mesh, job, cancel=cancel)
        if final:
            self.warm_ups.made(ratio)
        edges = mesh_edges(result.triangles, len(result.vertices))
        flags = {}
        if any(len(pairs) for pairs in self._edge_flags.values()):
            kept = np.asarray(result.kept, dtype=np.int64)
            moved = np.any(np.asarray(result.vertices) != self.prepared.arrays.vertices[kept], axis=1)
            flags = edge_flags.output_edge_flags(self._edge_flags, edges.vertices, kept, moved)
        return self.key(ratio, final), result, edges, time.perf_counter() - start, flags

    def _warm_up(self, ratio: float, cancel: CancelFlag) -> bool:
        """WarmUps' engine call: the chosen settings' warm-up toward ``ratio`` (worker)."""
        mesh = self.prepared.mesh
        return warm_up(mesh, pipeline.engine_job(mesh, {"ratio": ratio}, self.options, self.guidance), cancel)

    def _make_preview(self) -> None:
        """The preview object, beside the hidden original (main thread, first result)."""
        obj = self.obj
        self.mesh = bpy.data.meshes.new(obj.name + PREVIEW_SUFFIX)
        for material in obj.data.materials:
            self.mesh.materials.append(material)
        self.preview = bpy.data.objects.new(obj.name + PREVIEW_SUFFIX, self.mesh)
        for collection in obj.users_collection or (bpy.context.scene.collection,):
            collection.objects.link(self.preview)
        self.preview.matrix_world = obj.matrix_world.copy()
        self.preview.show_wire = True      # at 10 % one judges the mesh by its edges
        self.preview.show_all_edges = True
        obj.hide_set(True)

    def show(self, key, result, edges, seconds: float, flags: dict = None) -> None:
        """Puts a result into the preview object (main thread); key: ratio or (ratio, final);
        flags: its edges' seam and sharp flags (edge_flags.output_edge_flags)."""
        start = time.perf_counter()
        ratio, final = key if isinstance(key, tuple) else (key, False)
        if self.preview is None:
            self._make_preview()
        mesh_write.fill_geometry(self.mesh, result.vertices, result.triangles, edges)
        if flags and len(self.mesh.edges) == len(edges):  # (Blender's own edge pass: other edges)
            edge_flags.write_edge_flags(self.mesh, flags)
        self.ratio, self.final, self.result, self.seconds_decimate = ratio, final, result, seconds
        self.seconds_write = time.perf_counter() - start

    def update(self, ratio: float, final: bool = False) -> None:
        """Synchronous update (benchmarks, tests); waits for the preparation first."""
        self.wait_prepared()
        self.show(*self.compute(ratio, final))
        with self._lock:
            self._started = self._asked = self.key(ratio, final)
            self._asked_at = time.perf_counter()

    @property
    def direct(self) -> bool:
        """True when the drag asks for the chosen settings' result itself (it is fast enough)."""
        return self.final_seconds is not None and self.final_seconds <= DIRECT_SECONDS

    def request(self, ratio: float, final: bool = False) -> None:
        """Asks for ``ratio`` (a draft while dragging, or the chosen settings' result when
        ``direct``; ``final``: the chosen settings); only the latest request is computed (after
        the preparation, if it still runs). Back at the ratio whose chosen-settings result is on
        screen, that result stays: nothing is computed and the results still on their way are
        dropped; one kept from earlier is shown again without computing."""
        final = final or self.direct
        with self._lock:
            now = time.perf_counter()
            if now - self._asked_at < EVENT_GAP:  # within a drag (a loaded machine spaces its events)
                self._interval = 0.7 * self._interval + 0.3 * (now - self._asked_at)
            self._asked, self._asked_at = self.key(ratio, final), now
            self._highest = max(self._highest, ratio)
            if self.final and ratio == self.ratio:
                self._pending = self._finished = self._started = None
                self._shown_order = self._started_count
                return
            if self._finished is not None and self._finished[1][0] == self.key(ratio, True):
                self._pending = None  # that result is about to be shown
                return
            if self._speculation is not None:
                if self._speculation[0][0] != ratio:  # the drag moved on: stop it in the engine
                    self._speculation[1].set()
                elif final and not self._speculation[1].is_set:  # the rest takes over the one running
                    self._pending = None
                    return
            kept = self._kept.get(ratio) if final else None
            if kept is not None:  # computed before: it becomes the newest result
                self._pending, self._started = None, self._asked
                self._started_count += 1
                self._finished = (self._started_count, kept)
                self._kept.move_to_end(ratio)
                return
            self._pending = self._asked
        self._new_request.set()
        self._start_worker()

    def _start_worker(self) -> None:
        with self._lock:
            if (self.prepared is not None and self._workers < WORKERS and self._pending is not None
                    and self._pending != self._started and not self._cancel.is_set()):
                self._workers += 1
                self._pool.submit(self._work)

    def _work(self) -> None:
        """Worker loop: computes the latest pending request until none is new, then the latest
        ratio's chosen-settings result ahead of the rest (SPECULATE)."""
        while True:
            self._stagger()
            with self._lock:
                key, self._pending = self._pending, None
                if key is None or key == self._started or self._cancel.is_set():
                    self._new_request.clear()
                    (speculation, wait), order = self._speculation_to_start(), 0
                    warm = self._warm_up_to_start() if speculation is None else None
                    if speculation is None and wait is None and warm is None:
                        self._workers -= 1
                        return
                    wait = None if warm is not None else wait
                    self._waiting += wait is not None or warm is not None
                else:
                    speculation, wait, warm, order = None, None, None, self._mark_started(key)
            if warm is not None:  # idle meanwhile: what the rest will resume from (not staggered against)
                self.warm_ups.run(warm)
                with self._lock:
                    self._waiting -= 1
            elif wait is not None:  # the drag may only be between two events: look again then (or at one)
                self._new_request.wait(wait)
                with self._lock:
                    self._waiting -= 1
            elif not (self._speculate(*speculation) if speculation else self._compute_request(key, order)):
                return

    def _mark_started(self, key) -> int:
        """Records that ``key`` starts now (under the lock); its order number."""
        self._started = key
        self._started_count += 1
        self._last_start = time.perf_counter()
        return self._started_count

    def _compute_request(self, key, order: int) -> bool:
        """Computes a request (worker) and hands it to the main thread unless a newer one was;
        False when the worker ends (an error, or the session closed)."""
        try:
            finished = self.compute(*key)
        except Exception as error:  # noqa: BLE001 - handed to the main thread
            with self._lock:
                self._error, self._started = error, None
                self._workers -= 1
            return False
        with self._lock:
            if self._cancel.is_set():  # closed meanwhile: the result ends unseen
                self._workers -= 1
                return False
            seconds = finished[3]
            self._typical = 0.7 * self._typical + 0.3 * seconds if self._typical else seconds
            if key[1]:
                self._keep(key[0], seconds, finished)
            # A newer result replaces one not shown yet; an older one than shown is dropped.
            newest = self._finished[0] if self._finished else self._shown_order
            sources = False
            if order > newest:
                self._finished = (order, finished)
                if key[1] and key == self._asked:  # a result Enter may write: its attribute sources
                    self._sources, sources = (finished[1], None), True
        if sources:
            self._find_sources(finished[1])
        return True

    def _speculation_to_start(self):
        """For a worker with nothing else to do (under the lock): ((key, CancelFlag), None) of the
        latest drag ratio's chosen-settings computation when it should start it, (None, seconds)
        when it should look again in that many seconds, (None, None) when it may end."""
        asked = self._asked
        if (not SPECULATE or self._speculation is not None or asked is None or asked[1] or self.direct
                or self._cancel.is_set() or asked[0] in self._kept or (self.final and self.ratio == asked[0])):
            return None, None
        pause = min(REST_SECONDS, max(SPECULATE_AFTER, 2 * self._interval))
        wait = pause - (time.perf_counter() - self._asked_at)
        if wait > 0:
            return None, wait
        self._speculation = (self.key(asked[0], True), CancelFlag())
        return self._speculation, None

    def _warm_up_to_start(self) -> Optional[float]:
        """For a worker with nothing else to do (under the lock): the ratio to warm the chosen
        settings' computation up toward (WarmUps.next), or None: not for a rest, whose own
        computation is asked already."""
        asked = self._asked
        if asked is None or asked[1] or self.direct or self._cancel.is_set() or asked[0] in self._kept:
            return None
        return self.warm_ups.next(self._highest)

    def _speculate(self, key, cancel: CancelFlag) -> bool:
        """Computes a speculation (worker): kept like any chosen-settings result, and shown when
        the drag is still at its ratio; dropped when cancelled. False when the worker ends (an
        error, or the session closed)."""
        finished = error = None
        try:
            finished = self.compute(*key, cancel=cancel)
        except Cancelled:
            pass
        except Exception as failure:  # noqa: BLE001 - handed to the main thread
            error = failure
        with self._lock:
            self._speculation = None
            if error is not None or self._cancel.is_set():
                self._error, self._workers = error or self._error, self._workers - 1
                return False
            if finished is None:
                return True
            self._keep(key[0], finished[3], finished)
            shown = self._asked is not None and self._asked[0] == key[0]
            if shown:  # newer than anything computed for the drag so far
                self._started_count += 1
                self._finished = (self._started_count, finished)
                self._sources = (finished[1], None)
        if shown:
            self._find_sources(finished[1])
        return True

    def _keep(self, ratio: float, seconds: float, finished) -> None:
        """Remembers a chosen-settings computation and its seconds (worker, under the lock)."""
        self.final_seconds = self.prepared.final_seconds[self._options_key] = seconds
        self._kept[ratio] = finished
        self._kept.move_to_end(ratio)
        while len(self._kept) > KEPT_RESULTS:
            self._kept.popitem(last=False)

    def _stagger(self) -> None:
        """Spreads the workers' starts over one computation's time, so that their results
        arrive evenly instead of in pairs (and each starts from a newer request). A rested
        drag's request starts at once."""
        with self._lock:
            resting = self._pending is not None and self._pending[1] and not self.direct
            if self._workers - self._waiting < 2 or not self._typical or resting or self._pending is None:
                return
            wait = self._typical / WORKERS - (time.perf_counter() - self._last_start)
        if wait > 0:
            time.sleep(wait)

    def _take_finished(self):
        """The newest finished (order, result) not yet taken, or None (main thread). A worker's
        error is raised here, so engine errors surface on the main thread; a request that came
        while a worker was stopping gets a worker."""
        with self._lock:
            finished, self._finished = self._finished, None
            error, self._error = self._error, None
            if finished:
                self._shown_order = finished[0]
        if error is not None:
            raise error
        self._start_worker()
        return finished

    def poll(self) -> bool:
        """Shows the newest finished result (main thread); True when the view changed.

        The workers are already computing the next requests meanwhile, if there are any. A
        failed preparation or decimation raises here (DecimationError, or the engine's error)."""
        finished = self._take_finished()
        if finished:
            self.show(*finished[1])
        with self._lock:
            rested = (self.ratio is not None and self._asked is not None and not self._asked[1]
                      and time.perf_counter() - self._asked_at >= REST_SECONDS)
            asked = self._asked
        if rested:  # the drag rests: its ratio with the chosen settings, while any draft finishes
            self.request(asked[0], final=True)
        return finished is not None

    @property
    def busy(self) -> bool:
        with self._lock:
            return self._workers > 0 or self._finished is not None

    # -- applying ------------------------------------------------------------------------------

    def apply(self, ratio: float):
        """Enter: the pipeline Run to write, at ``ratio`` with the chosen settings.

        When the result shown was made with exactly those (the chosen mode's result after the drag
        rested at this ratio, or any result when the chosen settings are the fast ones) it is the
        one written: no second decimation. Otherwise it is computed on a worker like any request.
        The Run also carries where moved vertices take their attributes from (numpy work that
        takes seconds on big quality results), found on a worker as soon as such a result is
        computed. Returns None while either is on its way; ``poll_apply`` then gives the Run."""
        key = self.key(ratio, True)
        with self._lock:
            self._applying = key
            self._to_apply = None
            if self.result is not None and (self.ratio, self.final) == key:
                self._to_apply = (ratio, self.result, self.seconds_decimate)
        self.apply_started = time.perf_counter()
        if self._to_apply is None:
            self.request(ratio, final=True)
        return self.poll_apply()

    @property
    def applying(self) -> bool:
        """True while the result to apply (or its attribute sources) is being computed."""
        return self._applying is not None

    @property
    def apply_computed(self) -> bool:
        """True once the result to apply is computed (only its attribute sources are awaited)."""
        return self._to_apply is not None

    def poll_apply(self):
        """While applying (main thread): the Run once its result and attribute sources are ready,
        else None. Results of the drag that finish meanwhile are dropped (the preview is about to
        go); a failed decimation raises here."""
        finished = self._take_finished()
        if self._applying is None:
            return None
        if self._to_apply is None and finished is not None and finished[1][0] == self._applying:
            (ratio, _final), result, _edges, seconds, _flags = finished[1]
            self._to_apply = (ratio, result, seconds)
        if self._to_apply is None:
            return None
        ratio, result, seconds = self._to_apply
        moved = self._sources_of(result)
        if moved is None:
            return None
        self._applying = self._to_apply = None
        return self._run(ratio, result, seconds, moved)

    def _find_sources(self, result) -> None:
        """Where the moved vertices of ``result`` take their attributes from (any thread)."""
        arrays = self.prepared.arrays
        try:
            moved = moved_vertices(arrays.vertices, arrays.triangles, result)
        except Exception as error:  # noqa: BLE001 - handed to the main thread
            with self._lock:
                self._error = error
            return
        with self._lock:
            if self._sources is not None and self._sources[0] is result:
                self._sources = (result, moved)

    def _sources_of(self, result):
        """The attribute sources of ``result`` when found, else None (a worker finds them: the one
        that computed it, or one started here for a result computed elsewhere)."""
        with self._lock:
            if self._sources is not None and self._sources[0] is result:
                return self._sources[1]
            self._sources = (result, None)
        self._pool.submit(self._find_sources, result)
        return None

    def _run(self, ratio: float, result, seconds: float, moved):
        """The pipeline Run of a result of this session (what pipeline.write_output takes)."""
        return pipeline.make_run(self.obj, self.prepared, self.guidance, result, {"ratio": ratio}, self.options,
                                 seconds, dict(self.settings, target_mode="RATIO", ratio=ratio), moved)

    def close(self) -> None:
        """Removes the preview object and shows the original again. Returns at once: a running
        preparation is cancelled in the engine (at its next step) and a running decimation ends
        unseen; workers never touch Blender data, so nothing waits for them."""
        self._cancel.set()
        self._new_request.set()
        self.warm_ups.cancel()
        with self._lock:
            if self._speculation is not None:
                self._speculation[1].set()
            self._pending = self._applying = self._to_apply = self._finished = self._sources = None
        self._pool.shutdown(wait=False)
        if self.preview is not None:
            bpy.data.objects.remove(self.preview)
            bpy.data.meshes.remove(self.mesh)
            self.preview = self.mesh = None
            self.obj.hide_set(self.was_hidden)


def cancelled(error: BaseException) -> bool:
    """True for the engine's Cancelled (a preparation stopped by ``close``)."""
    return isinstance(error, Cancelled)
