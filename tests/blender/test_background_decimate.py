"""Guided Decimate on a worker thread (decimation/background.py, what the operator's modal polls):
the results are the operator's own decimations bit for bit, the progress names the object and
the step, a cancel stops the engine and leaves every object and the cache as they were, and a
failing object does not stop the others. The modal itself (timer, header, Esc, undo) runs in a
window under Xvfb (test_decimate_modal.py)."""

import bpy
import numpy as np
import pytest

import meshgen
from helpers import Params, make_object, snapshot


def background(ts):
    return ts.blender.decimation.background


def reads_of(ts, objects, **settings):
    pipeline = ts.blender.decimation.pipeline
    return [pipeline.read_input(bpy.context, obj, Params(**settings)) for obj in objects]


def assert_same_result(result, expected):
    for field in ("vertices", "triangles", "kept", "samples", "face_source"):
        np.testing.assert_array_equal(np.asarray(getattr(result, field)), np.asarray(getattr(expected, field)))


@pytest.fixture
def donuts(ts, scene):
    ts.blender.preview.cache.prepared_meshes.clear()
    return [make_object(f"Donut{i}", *meshgen.torus(64 + 16 * i, 32)) for i in range(2)]


@pytest.mark.parametrize("settings", [dict(ratio=0.1, quality="QUALITY", seed=3), dict(ratio=0.2, seed=4),
                                      dict(target_mode="MAX_ERROR", max_error=0.5, quality="FAST", seed=5)])
def test_the_worker_gives_the_operators_results(ts, donuts, settings):
    job = background(ts).BackgroundDecimation(reads_of(ts, donuts, **settings))
    assert job.wait(120) and job.progress()[0] == 1.0
    assert [failure for _run, failure in job.outcomes] == [None, None]
    for (run, _failure), obj, read in zip(job.outcomes, donuts, job.reads):
        assert run.obj == obj
        expected = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(**settings)).result
        assert_same_result(run.result, expected)
        vertices, kept = np.asarray(run.result.vertices), np.asarray(run.result.kept)
        moved = np.flatnonzero(np.any(vertices != read.arrays.vertices[kept], axis=1))
        np.testing.assert_array_equal(run.moved.moved, moved)  # found on the worker, for the write
        if "max_error" in settings:  # the search ran, and reported each probe
            assert run.result.error_bound is not None and len(run.result.error_bound.probes) > 1


def test_the_api_gives_the_same_result(ts, donuts):
    """The worker's result is the public API's on the same arrays."""
    job = background(ts).BackgroundDecimation(reads_of(ts, donuts[:1], ratio=0.15, quality="QUALITY", seed=6))
    assert job.wait(120)
    arrays = job.reads[0].arrays
    expected = ts.core.decimate(ts.core.Mesh(arrays.vertices, arrays.triangles), 0.15, seed=6, mode="quality",
                                adaptivity=0.5, density="off")
    assert_same_result(job.outcomes[0][0].result, expected)


class Gate:
    """Wraps the preparation's progress callback: holds the worker at its first report until opened."""

    def __init__(self, monkeypatch, module):
        import threading

        self.reached, self.open = threading.Event(), threading.Event()
        original = module.BackgroundDecimation._preparing

        def preparing(job, index):
            told = original(job, index)

            def held(fraction, stage):
                self.reached.set()
                self.open.wait(30)
                return told(fraction, stage)
            return held

        monkeypatch.setattr(module.BackgroundDecimation, "_preparing", preparing)


def test_cancel_while_preparing_stops_the_engine_and_changes_nothing(ts, donuts, monkeypatch):
    module = background(ts)
    gate = Gate(monkeypatch, module)
    before = [snapshot(obj.data) for obj in donuts]
    objects = sorted(bpy.data.objects.keys())
    cache = ts.blender.preview.cache.prepared_meshes
    misses = cache.misses
    job = module.BackgroundDecimation(reads_of(ts, donuts, ratio=0.1))
    try:
        assert gate.reached.wait(30)
        fraction, line = job.progress()
        assert fraction < 0.5 and "'Donut0'" in line and "1 of 2" in line and "preparing" in line
        assert not job.finished()
        job.cancel()
    finally:
        gate.open.set()
    assert job.wait(30) and job.outcomes == [] and job.cancelled
    assert [snapshot(obj.data) for obj in donuts] == before and sorted(bpy.data.objects.keys()) == objects
    assert cache.misses == misses + 1 and not cache._entries  # stopped in the engine: nothing cached


def test_cancel_during_a_decimation_stops_the_engine(ts, donuts, monkeypatch):
    """Esc once the mesh is prepared: the decimation running gets Cancelled from the engine."""
    module, pipeline = background(ts), ts.blender.decimation.pipeline
    original, raised, jobs = pipeline.run_engine, [], []

    def run_engine(mesh, job, progress=None, cancel=None):
        jobs[0].cancel()  # as if Esc came while the engine runs
        try:
            return original(mesh, job, progress, cancel)
        except BaseException as error:
            raised.append(error)
            raise

    monkeypatch.setattr(pipeline, "run_engine", run_engine)
    before = snapshot(donuts[0].data)
    jobs.append(module.BackgroundDecimation(reads_of(ts, donuts[:1], ratio=0.1, quality="QUALITY", seed=2),
                                            deferred=True))
    jobs[0].begin()
    assert jobs[0].wait(30) and jobs[0].outcomes == [] and jobs[0].cancelled
    assert len(raised) == 1 and isinstance(raised[0], ts.core.api.loops.Cancelled)
    assert snapshot(donuts[0].data) == before


def test_cancel_during_an_error_search_stops_at_the_next_probe(ts, donuts, monkeypatch):
    module = background(ts)
    probes = []

    class CancelAtFirstProbe(module.BackgroundDecimation):
        def _searching(self, index):
            told = super()._searching(index)

            def first(*args):
                probes.append(args)
                self.cancel()
                answer = told(*args)
                probes.append(self.progress()[1])
                return answer
            return first

    before = snapshot(donuts[0].data)
    job = CancelAtFirstProbe(reads_of(ts, donuts[:1], target_mode="MAX_ERROR", max_error=0.5, seed=7))
    assert job.wait(60) and job.outcomes == []
    assert len(probes) == 2 and probes[0][0] == 1 and "max deviation: probe 1" in probes[1]
    assert snapshot(donuts[0].data) == before


def test_a_failing_object_does_not_stop_the_others(ts, donuts):
    """A one-line failure of the worker's part (here turning the guidance read into engine
    arguments) is that object's outcome; the next object is decimated all the same."""
    reads = reads_of(ts, donuts, ratio=0.2)

    def failing():
        raise ts.blender.decimation.guidance.GuidanceError("'Donut0': the guidance could not be made")
    reads[0].read_guidance = failing
    job = background(ts).BackgroundDecimation(reads)
    assert job.wait(60)
    (nothing, failure), (run, none) = job.outcomes
    assert nothing is None and failure == "'Donut0': the guidance could not be made"
    assert none is None and run.obj == donuts[1] and run.result.num_vertices > 0
