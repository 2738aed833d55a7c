"""Live Preview apply (Enter) at the session level: a result shown with exactly the settings being
applied is written as it is (the engine is not called again), any other is computed on the
preview's worker while the main thread stays free, and closing the preview then writes nothing
and leaves no thread. The modal itself (events, cursor, undo) is driven in a window by
preview_script.py (test_preview_modal.py).

Engine calls are counted by wrapping pipeline.run_engine, which every preview computation goes
through; the final computation can be held by a gate in that wrapper, so that "still computing"
is a fact of the test, not a race against the machine's speed."""

import threading
import time

import bpy
import numpy as np
import pytest

import meshgen
from helpers import EngineCalls, Params, make_object, positions, snapshot, wait_for


def preview_threads():
    return [t for t in threading.enumerate() if t.name.startswith("topstoc-preview")]


def triangles_of(mesh):
    return np.array([tuple(p.vertices) for p in mesh.polygons])


def reference(ts, obj, ratio, quality, seed):
    """The same decimation through the operator's pipeline (main thread, its own engine call)."""
    pipeline = ts.blender.decimation.pipeline
    return pipeline.decimate(bpy.context, obj, Params(ratio=ratio, quality=quality, seed=seed)).result


@pytest.fixture
def donut(ts, scene):
    ts.blender.preview.cache.prepared_meshes.clear()
    return make_object("Donut", *meshgen.torus(96, 48))


def test_a_rested_quality_result_is_applied_as_shown(ts, scene, donut, monkeypatch):
    preview, pipeline = ts.blender.preview.session, ts.blender.decimation.pipeline
    engine = EngineCalls(monkeypatch, pipeline)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=3), ratio=0.1)
    try:
        assert wait_for(lambda: session.poll() or session.final)  # the fast result, then the rested quality one
        assert wait_for(lambda: (session.poll(), session.final)[1]), engine.calls
        assert wait_for(lambda: not session.busy) and session.ratio == 0.1  # its attribute sources found too
        assert [call.mode for call in engine.calls] == ["fast", "quality"]
        shown_vertices = positions(session.mesh).copy()
        shown_triangles = triangles_of(session.mesh)
        session.request(0.1)  # a mouse move that ends at the same ratio keeps the Quality result
        assert not session.busy and not session.poll() and session.final and engine.count() == 2
        run = session.apply(0.1)
        assert run is not None and not session.applying
        assert engine.count() == 2  # no second decimation
        assert run.moved is not None and len(run.moved.moved) > 50  # found on the worker, for the write
    finally:
        session.close()
    written = []
    monkeypatch.setattr(pipeline, "moved_vertices_of", lambda *args: written.append(args))
    out = pipeline.write_output(run)
    assert not written  # the write did not look for them again
    np.testing.assert_array_equal(positions(out.data), shown_vertices)
    np.testing.assert_array_equal(triangles_of(out.data), shown_triangles)
    # ... and that is the Quality result at 10 %: the operator's own decimation gives the same samples
    expected = reference(ts, donut, 0.1, "QUALITY", 3)
    np.testing.assert_array_equal(np.asarray(run.result.samples), np.asarray(expected.samples))
    np.testing.assert_array_equal(positions(out.data), np.asarray(expected.vertices, dtype=np.float32))
    moved = np.any(np.asarray(expected.vertices) != positions(donut.data).astype(np.float64)[expected.kept], axis=1)
    assert moved.any()  # a quality result (placement moved vertices), not the fast one
    assert out["topstoc_source"] == "Donut" and out.topstoc.source == donut
    assert '"ratio": 0.1' in out["topstoc_parameters"] and '"mode": "quality"' in out["topstoc_parameters"]


def test_with_fast_chosen_the_drag_shows_drafts_and_the_rested_result_is_applied_as_shown(ts, scene, donut,
                                                                                          monkeypatch):
    """Drag frames are drafts (no attribute sources, no final output check); the rested result
    is the full fast decimation, checked, with the draft's geometry, and Enter writes it as shown."""
    preview = ts.blender.preview.session
    monkeypatch.setattr(preview, "SPECULATE", False)  # the full result only once the drag rests
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="FAST", seed=2), ratio=0.1)
    try:
        assert wait_for(lambda: session.poll())
        session.request(0.2)
        assert wait_for(lambda: (session.poll(), session.ratio)[1] == 0.2)
        draft = session.result
        assert not session.final and not draft.stats.output_checked and draft.stats.topology_kept is None
        assert len(draft.face_source) == len(draft.labels) == 0
        assert wait_for(lambda: (session.poll(), session.final)[1])  # the drag rested
        rested = session.result
        assert rested.stats.output_checked and rested.stats.topology_kept
        np.testing.assert_array_equal(rested.triangles, draft.triangles)
        np.testing.assert_array_equal(rested.vertices, draft.vertices)
        assert wait_for(lambda: not session.busy)
        calls = engine.count()
        run = session.apply(0.2)
        assert run is not None and len(run.moved.moved) == 0  # Fast: no vertex moved
        assert run.result is rested and engine.count() == calls == 3  # 0.1, 0.2 drafts; 0.2 in full
    finally:
        session.close()
    expected = reference(ts, donut, 0.2, "FAST", 2)
    np.testing.assert_array_equal(np.asarray(run.result.samples), np.asarray(expected.samples))
    np.testing.assert_array_equal(np.asarray(run.result.face_source), np.asarray(expected.face_source))


def test_applying_during_a_drag_computes_the_chosen_settings_on_the_worker(ts, scene, donut, monkeypatch):
    preview = ts.blender.preview.session
    monkeypatch.setattr(preview, "SPECULATE", False)  # no quality computation before Enter's
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=5), ratio=0.1)
    try:
        assert wait_for(lambda: session.poll())
        assert session.ratio == 0.1 and not session.final
        engine.gate.clear()          # the final computation waits until the test lets it go
        session.request(0.17)        # the drag goes on ...
        start = time.perf_counter()
        assert session.apply(0.17) is None   # ... and Enter comes before anything at 0.17 shows
        assert time.perf_counter() - start < 0.5
        assert engine.held.wait(10) and session.applying
        assert session.poll_apply() is None  # the main thread is free while the worker computes
        call = next(call for call in engine.calls if call.mode == "quality")
        assert call.target.ratio == 0.17 and call.thread.startswith(preview.THREAD_PREFIX)
        engine.gate.set()
        runs = []
        assert wait_for(lambda: runs.append(session.poll_apply()) or runs[-1] is not None)
        run = runs[-1]
        assert engine.count("quality") == 1 and not session.applying
        assert session.ratio == 0.1  # the preview was not redrawn with results about to be dropped
    finally:
        engine.gate.set()
        session.close()
    expected = reference(ts, donut, 0.17, "QUALITY", 5)
    np.testing.assert_array_equal(np.asarray(run.result.samples), np.asarray(expected.samples))
    np.testing.assert_array_equal(np.asarray(run.result.vertices), np.asarray(expected.vertices))
    out = ts.blender.decimation.pipeline.write_output(run)
    assert len(out.data.vertices) == expected.num_vertices
    assert wait_for(lambda: not preview_threads(), 10), preview_threads()


def test_applying_uses_the_quality_result_still_being_computed(ts, scene, donut, monkeypatch):
    """Enter while the rested quality result is on its way: that computation is the one applied."""
    preview = ts.blender.preview.session
    monkeypatch.setattr(preview, "SPECULATE", False)  # the rest starts it (test_preview_speculation.py: ahead of it)
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=1), ratio=0.1)
    try:
        assert wait_for(lambda: session.poll())
        engine.gate.clear()
        assert wait_for(lambda: (session.poll(), engine.held.is_set())[1])  # the rest started it
        assert session.apply(0.1) is None and session.applying
        engine.gate.set()
        runs = []
        assert wait_for(lambda: runs.append(session.poll_apply()) or runs[-1] is not None)
        assert engine.count("quality") == 1
    finally:
        engine.gate.set()
        session.close()


def test_closing_while_applying_writes_nothing_and_leaves_no_thread(ts, scene, donut, monkeypatch):
    preview = ts.blender.preview.session
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline)
    before = snapshot(donut.data)
    names = set(bpy.data.objects.keys())
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=5), ratio=0.1)
    try:
        assert wait_for(lambda: session.poll())
        engine.gate.clear()
        assert session.apply(0.3) is None
        assert engine.held.wait(10) and session.applying
        start = time.perf_counter()
        session.close()                  # Esc: returns at once although the engine is held
        assert time.perf_counter() - start < 1.0
    finally:
        engine.gate.set()                # the engine finishes its call; the result is dropped
    assert wait_for(lambda: not preview_threads(), 10), preview_threads()
    assert session.poll_apply() is None
    assert set(bpy.data.objects.keys()) == names and not donut.hide_get()
    assert snapshot(donut.data) == before


def test_enter_before_the_attribute_sources_are_found_waits_for_them(ts, scene, donut, monkeypatch):
    """The rested Quality result shows before the worker has found where its moved vertices take
    their attributes from: Enter then waits for that (no new decimation), on the modal's timer."""
    preview = ts.blender.preview.session
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline)
    gate, held, threads = threading.Event(), threading.Event(), []
    find = preview.moved_vertices

    def held_moved_vertices(*args):
        threads.append(threading.current_thread().name)
        held.set()
        gate.wait(30)
        return find(*args)

    monkeypatch.setattr(preview, "moved_vertices", held_moved_vertices)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=6), ratio=0.1)
    try:
        assert wait_for(lambda: (session.poll(), session.final)[1] and held.is_set())
        assert session.apply(0.1) is None and session.applying and session.apply_computed
        assert session.poll_apply() is None
        gate.set()
        runs = []
        assert wait_for(lambda: runs.append(session.poll_apply()) or runs[-1] is not None)
        assert len(runs[-1].moved.moved) > 50 and not session.applying
        assert engine.count() == 2  # fast, quality: nothing decimated again
        assert threads and all(t.startswith(preview.THREAD_PREFIX) for t in threads)  # not the main thread
    finally:
        gate.set()
        session.close()


def test_a_rested_symmetric_result_is_applied_as_shown(ts, scene, donut, monkeypatch):
    """Symmetry with Fast chosen: the drag shows plain Fast results, the rest the mirrored one,
    which Enter writes without decimating again."""
    preview = ts.blender.preview.session
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline)
    params = Params(quality="FAST", seed=2, use_symmetry=True, symmetry_axis="X")
    session = preview.PreviewSession(bpy.context, donut, params, ratio=0.1)
    try:
        assert wait_for(lambda: (session.poll(), session.final)[1]) and wait_for(lambda: not session.busy)
        calls = engine.count()
        run = session.apply(0.1)
        assert run is not None and engine.count() == calls == 2
    finally:
        session.close()
    expected = ts.blender.decimation.pipeline.decimate(bpy.context, donut, params).result
    np.testing.assert_array_equal(np.asarray(run.result.vertices), np.asarray(expected.vertices))
    assert run.parameters["symmetry"] == "X"
    co = np.asarray(run.result.vertices)
    mirrored = {tuple(np.round(p * [-1, 1, 1], 5)) for p in co}
    assert mirrored == {tuple(np.round(p, 5)) for p in co}  # the result is mirror-symmetric
