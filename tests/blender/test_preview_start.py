"""Live Preview start off the main thread: creating a session returns before the mesh is prepared,
nothing in the scene changes before the first result, a cancelled preparation stops in the
engine and leaves the object as it was, and a prepared mesh is not prepared again.

The preparation is held at one of its steps by a gate in the engine's progress callback (the
session's ``_report``), so that "still preparing" is a fact of the test, not a race against the
machine's speed."""

import threading
import time

import bpy
import pytest

import meshgen
from helpers import Params, make_object, snapshot, wait_for


def gated_report(monkeypatch, preview_module, hold_at):
    """Makes the engine wait at step ``hold_at`` of the preparation until the returned gate opens;
    returns (gate, steps seen, event set when the engine reached the step)."""
    gate, reached, steps = threading.Event(), threading.Event(), []
    original = preview_module.PreviewSession._report

    def report(self, fraction, stage):
        steps.append(stage)
        original(self, fraction, stage)  # the session sees the step before the engine is held
        if stage == hold_at:
            reached.set()
            gate.wait(30)
        return original(self, fraction, stage)  # asked again: a close() meanwhile says stop

    monkeypatch.setattr(preview_module.PreviewSession, "_report", report)
    return gate, steps, reached


def preview_threads():
    return [t for t in threading.enumerate() if t.name.startswith("topstoc-preview")]


def test_session_returns_before_the_preparation_and_shows_the_first_result(ts, scene, monkeypatch):
    preview = ts.blender.preview.session
    ts.blender.preview.cache.prepared_meshes.clear()
    obj = make_object("Donut", *meshgen.torus(96, 48))
    gate, steps, reached = gated_report(monkeypatch, preview, "validate")
    threading.Timer(10, gate.set).start()  # a session that waited would still end, later
    start = time.perf_counter()
    session = preview.PreviewSession(bpy.context, obj, Params(seed=3), ratio=0.1)
    returned = time.perf_counter() - start
    try:
        assert returned < 5, returned
        assert reached.wait(10) and session.preparing
        assert session.progress() == (0.0, "validate")
        assert not session.poll()                       # nothing to show yet ...
        assert session.preview is None and not obj.hide_get()
        assert "Donut" + preview.PREVIEW_SUFFIX not in bpy.data.objects  # ... and nothing made
        gate.set()
        assert wait_for(lambda: session.poll())
        assert not session.preparing
        assert steps == ["validate", "order", "adjacency", "normals and weights", "components"]
        expected = session.prepared.mesh.decimate(ratio=0.1, seed=3, mode="fast")
        assert session.ratio == 0.1 and len(session.mesh.vertices) == expected.num_vertices
        assert len(session.mesh.polygons) == expected.num_triangles
        assert obj.hide_get() and session.preview.show_wire
    finally:
        gate.set()
        session.close()
    assert not obj.hide_get() and "Donut" + preview.PREVIEW_SUFFIX not in bpy.data.objects


def test_a_request_during_the_preparation_is_the_first_result(ts, scene, monkeypatch):
    preview = ts.blender.preview.session
    monkeypatch.setattr(preview, "SPECULATE", False)  # only the requests are computed
    ts.blender.preview.cache.prepared_meshes.clear()
    obj = make_object("Donut", *meshgen.torus(64, 32))
    gate, _steps, reached = gated_report(monkeypatch, preview, "order")
    session = preview.PreviewSession(bpy.context, obj, Params(seed=1), ratio=0.1)
    try:
        assert reached.wait(10)
        session.request(0.25)  # the user drags while the mesh is being prepared
        gate.set()
        assert wait_for(lambda: (session.poll(), session.ratio)[1] == 0.25)
        assert wait_for(lambda: not session.busy)
        assert not session.poll() and session.ratio == 0.25
        assert session._started_count == 1  # 0.1 was replaced before it started
    finally:
        gate.set()
        session.close()


def test_close_during_preparation_stops_the_engine_and_leaves_the_object(ts, scene, monkeypatch):
    preview = ts.blender.preview.session
    cache = ts.blender.preview.cache.prepared_meshes
    cache.clear()
    obj = make_object("Donut", *meshgen.torus(96, 48))
    before = snapshot(obj.data)
    gate, steps, reached = gated_report(monkeypatch, preview, "adjacency")
    session = preview.PreviewSession(bpy.context, obj, Params(seed=3), ratio=0.1)
    assert reached.wait(10) and session.preparing
    misses = cache.misses
    start = time.perf_counter()
    session.close()                     # Esc: returns at once although the engine is held
    assert time.perf_counter() - start < 1.0
    gate.set()                          # the engine resumes and hears "stop" at its next step
    assert wait_for(lambda: session.start.done(), 10)
    error = session.start.exception()
    assert preview.cancelled(error), error
    assert "adjacency" in str(error)
    assert steps == ["validate", "order", "adjacency"]  # no step ran after the one refused
    assert wait_for(lambda: not preview_threads(), 10), preview_threads()
    assert cache.misses == misses and not cache._entries  # nothing half-prepared was kept
    assert snapshot(obj.data) == before and not obj.hide_get()
    assert "Donut" + preview.PREVIEW_SUFFIX not in bpy.data.objects


def test_a_prepared_mesh_is_not_prepared_again(ts, scene, monkeypatch):
    preview = ts.blender.preview.session
    cache = ts.blender.preview.cache.prepared_meshes
    cache.clear()
    obj = make_object("Donut", *meshgen.torus(64, 32))
    first = preview.PreviewSession(bpy.context, obj, Params(), ratio=0.2)
    first.update(0.2)
    first.close()
    hits = cache.hits
    steps = []
    original = preview.PreviewSession._report
    monkeypatch.setattr(preview.PreviewSession, "_report",
                        lambda self, fraction, stage: steps.append(stage) or original(self, fraction, stage))
    second = preview.PreviewSession(bpy.context, obj, Params(), ratio=0.2)
    try:
        assert wait_for(lambda: second.poll())
        assert cache.hits == hits + 1 and steps == []   # found in the cache: no engine preparation
        assert second.prepared is first.prepared
    finally:
        second.close()


def test_a_failed_preparation_surfaces_on_poll(ts, scene):
    preview = ts.blender.preview.session
    # a coordinate Blender holds but the engine refuses (found while preparing, on the worker)
    obj = make_object("Flat", [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [(0, 1, 2), (1, 3, 2)])
    obj.data.vertices[3].co = (float("nan"), 1.0, 0.0)
    session = preview.PreviewSession(bpy.context, obj, Params(), ratio=0.5)
    try:
        with pytest.raises(ts.blender.decimation.pipeline.DecimationError, match="'Flat'.*finite"):
            assert wait_for(lambda: session.poll() and False, 10)
    finally:
        session.close()
    assert not obj.hide_get()


def test_a_guidance_error_stops_the_started_preparation(ts, scene):
    preview = ts.blender.preview.session
    ts.blender.preview.cache.prepared_meshes.clear()
    obj = make_object("Donut", *meshgen.torus(64, 32))
    obj.topstoc.use_vertex_group, obj.topstoc.vertex_group = True, "no such group"
    before = snapshot(obj.data)
    with pytest.raises(ts.blender.decimation.guidance.GuidanceError, match="no such group"):
        preview.PreviewSession(bpy.context, obj, Params(), ratio=0.2)
    assert wait_for(lambda: not preview_threads(), 10), preview_threads()
    assert snapshot(obj.data) == before and not obj.hide_get()
    assert "Donut" + preview.PREVIEW_SUFFIX not in bpy.data.objects
