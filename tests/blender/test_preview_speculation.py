"""Live Preview speculation: while the drag goes on, a worker with no draft to compute starts the
latest ratio's chosen-settings (Quality) result; the ratio moving on cancels it in the engine,
the rest takes over the one running, and Enter applies it. Every such result is bit for bit the
operator's own decimation at that ratio.

REST_SECONDS is set to a day where the rest must not be what brings the Quality result, and
engine calls are held with a gate where "still computing" matters; no wall time is asserted."""

import bpy
import numpy as np
import pytest

import meshgen
from helpers import EngineCalls, Params, make_object, wait_for

DAY = 86400.0


@pytest.fixture
def donut(ts, scene):
    ts.blender.preview.cache.prepared_meshes.clear()
    return make_object("Donut", *meshgen.torus(96, 48))


@pytest.fixture
def preview(ts, monkeypatch):
    module = ts.blender.preview.session
    monkeypatch.setattr(module, "DIRECT_SECONDS", 0.0)  # Quality counts as slow: the drag shows drafts
    monkeypatch.setattr(module, "REST_SECONDS", DAY)
    return module


def shown_until(session, condition):
    return wait_for(lambda: (session.poll(), condition())[1])


def quality_calls(engine):
    return [call for call in engine.calls if call.mode == "quality"]


def assert_is_the_operators_result(ts, obj, result, ratio, seed):
    expected = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=ratio, quality="QUALITY",
                                                                                seed=seed)).result
    np.testing.assert_array_equal(np.asarray(result.vertices), np.asarray(expected.vertices))
    np.testing.assert_array_equal(np.asarray(result.triangles), np.asarray(expected.triangles))
    np.testing.assert_array_equal(np.asarray(result.samples), np.asarray(expected.samples))


def test_the_quality_result_comes_during_the_drag_without_a_rest(ts, donut, preview, monkeypatch):
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: False)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=4), ratio=0.1)
    try:
        for ratio in (0.12, 0.15, 0.13):
            session.request(ratio)
            session.poll()
        assert shown_until(session, lambda: session.final and session.ratio == 0.13)
        calls = quality_calls(engine)
        assert calls and all(call.cancel is not None for call in calls)  # speculations, not rests
        assert calls[-1].target.ratio == 0.13 and not calls[-1].cancel.is_set
        assert all(call.cancel.is_set for call in calls if call.target.ratio != 0.13)
        assert_is_the_operators_result(ts, donut, session.result, 0.13, 4)
    finally:
        session.close()


def test_a_moved_ratio_cancels_the_speculation_in_the_engine(ts, donut, preview, monkeypatch):
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.mode == "quality")
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=5), ratio=0.1)
    try:
        assert shown_until(session, lambda: session.final and session.ratio == 0.1)  # the first speculation
        engine.gate.clear()
        session.request(0.12)
        assert wait_for(lambda: any(call.target.ratio == 0.12 for call in quality_calls(engine)))
        [held] = [call for call in quality_calls(engine) if call.target.ratio == 0.12]
        assert not held.cancel.is_set
        session.request(0.2)  # the drag moves on
        assert held.cancel.is_set
        engine.gate.set()  # the held call reaches the engine with its flag set: Cancelled
        assert shown_until(session, lambda: session.final and session.ratio == 0.2)
        assert_is_the_operators_result(ts, donut, session.result, 0.2, 5)
        calls = len(quality_calls(engine))
        session.request(0.12, final=True)  # nothing was kept at 0.12: computed now
        assert shown_until(session, lambda: session.final and session.ratio == 0.12)
        assert len(quality_calls(engine)) == calls + 1 and quality_calls(engine)[-1].target.ratio == 0.12
        assert_is_the_operators_result(ts, donut, session.result, 0.12, 5)
    finally:
        engine.gate.set()
        session.close()


def speculating_at(session, engine, ratio):
    """After the first speculation (at 0.1), the drag moves to ratio: its Quality call is held."""
    assert shown_until(session, lambda: session.final and session.ratio == 0.1)
    engine.gate.clear()
    session.request(ratio)
    assert wait_for(lambda: [call.target.ratio for call in quality_calls(engine)][-1:] == [ratio])


def test_the_rest_takes_over_the_speculation_running(ts, donut, preview, monkeypatch):
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.mode == "quality")
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=6), ratio=0.1)
    try:
        speculating_at(session, engine, 0.15)
        assert shown_until(session, lambda: session.ratio == 0.15 and not session.final)  # the draft
        monkeypatch.setattr(preview, "REST_SECONDS", 0.0)
        session.poll()  # the drag rests: its request is the speculation already running
        engine.gate.set()
        assert shown_until(session, lambda: session.final and session.ratio == 0.15)
        assert [call.target.ratio for call in quality_calls(engine)] == [0.1, 0.15]
        assert not any(call.cancel.is_set for call in quality_calls(engine) if call.target.ratio == 0.15)
        assert_is_the_operators_result(ts, donut, session.result, 0.15, 6)
    finally:
        engine.gate.set()
        session.close()


def test_enter_applies_the_speculation_still_being_computed(ts, donut, preview, monkeypatch):
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.mode == "quality")
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=7), ratio=0.1)
    try:
        speculating_at(session, engine, 0.17)
        assert session.apply(0.17) is None and session.applying
        engine.gate.set()
        runs = []
        assert wait_for(lambda: runs.append(session.poll_apply()) or runs[-1] is not None)
        assert [call.target.ratio for call in quality_calls(engine)].count(0.17) == 1
    finally:
        engine.gate.set()
        session.close()
    assert_is_the_operators_result(ts, donut, runs[-1].result, 0.17, 7)


def test_without_speculation_nothing_in_quality_runs_before_the_rest(ts, donut, preview, monkeypatch):
    """The counterpart of the first test: the Quality result there comes from the speculation."""
    monkeypatch.setattr(preview, "SPECULATE", False)
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: False)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=4), ratio=0.1)
    try:
        session.request(0.13)
        assert shown_until(session, lambda: session.ratio == 0.13 and not session.busy)
        assert not session.final and not quality_calls(engine)
    finally:
        session.close()
