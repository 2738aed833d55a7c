"""Live Preview at rest: the drag rests when no new ratio came for REST_SECONDS, and the chosen
settings' result then starts at once on a free worker (a draft still running is not waited
for); where that result is fast enough the drag shows it directly (no drafts); results are kept
per ratio. Every result shown as the chosen settings' is bit for bit the operator's own
decimation at that ratio.

The tests set the thresholds (REST_SECONDS, DIRECT_SECONDS) to 0 or to a day instead of relying
on the machine's speed, and hold engine calls with gates where "still computing" matters."""


import bpy
import numpy as np
import pytest

import meshgen
from helpers import EngineCalls, Params, make_object, wait_for

DAY = 86400.0


def shown_until(session, condition):
    return wait_for(lambda: (session.poll(), condition())[1])


def assert_is_the_operators_result(ts, obj, session, ratio, seed):
    """The result shown is the operator's Quality decimation at ``ratio``, bit for bit."""
    expected = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=ratio, quality="QUALITY",
                                                                                seed=seed)).result
    assert session.final and session.ratio == ratio
    np.testing.assert_array_equal(np.asarray(session.result.vertices), np.asarray(expected.vertices))
    np.testing.assert_array_equal(np.asarray(session.result.triangles), np.asarray(expected.triangles))
    np.testing.assert_array_equal(np.asarray(session.result.samples), np.asarray(expected.samples))


@pytest.fixture
def donut(ts, scene):
    ts.blender.preview.cache.prepared_meshes.clear()
    return make_object("Donut", *meshgen.torus(96, 48))


def drag(session, ratios):
    for ratio in ratios:
        session.request(ratio)
        session.poll()


def test_the_rest_is_the_absence_of_new_ratios_and_gives_the_quality_result(ts, donut, monkeypatch):
    preview = ts.blender.preview.session
    monkeypatch.setattr(preview, "SPECULATE", False)  # (test_preview_speculation.py: computed ahead of the rest)
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.draft)
    monkeypatch.setattr(preview, "REST_SECONDS", DAY)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=4), ratio=0.1)
    try:
        assert shown_until(session, lambda: session.ratio == 0.1)
        drag(session, [0.12, 0.15, 0.13])
        assert shown_until(session, lambda: session.ratio == 0.13 and not session.busy)
        assert not session.final and engine.count("quality") == 0  # never at rest: drafts only
        monkeypatch.setattr(preview, "REST_SECONDS", 0.0)
        assert shown_until(session, lambda: session.final)
        assert engine.count("quality") == 1 and engine.count(draft=True) == engine.count()  - 1
        assert_is_the_operators_result(ts, donut, session, 0.13, 4)
    finally:
        session.close()


@pytest.mark.skipif(__import__("os").cpu_count() < 2, reason="one preview worker: a rest waits for the draft")
def test_a_rest_does_not_wait_for_the_draft_still_running(ts, donut, monkeypatch):
    preview = ts.blender.preview.session
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.draft)
    monkeypatch.setattr(preview, "REST_SECONDS", DAY)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=5), ratio=0.1)
    try:
        assert shown_until(session, lambda: session.ratio == 0.1)
        engine.gate.clear()
        session.request(0.2)
        assert wait_for(engine.held.is_set)  # the draft at 0.2 runs (held)
        monkeypatch.setattr(preview, "REST_SECONDS", 0.0)
        assert shown_until(session, lambda: session.final)  # computed beside it
        assert_is_the_operators_result(ts, donut, session, 0.2, 5)
        engine.gate.set()
        assert wait_for(lambda: not session.busy)
        assert not session.poll() and session.final  # the late draft is dropped, not shown over it
    finally:
        engine.gate.set()
        session.close()


def test_a_fast_quality_result_is_what_the_drag_shows(ts, donut, monkeypatch):
    preview = ts.blender.preview.session
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.draft)
    monkeypatch.setattr(preview, "DIRECT_SECONDS", DAY)  # any measured Quality time is fast enough
    params = Params(quality="QUALITY", seed=6)
    session = preview.PreviewSession(bpy.context, donut, params, ratio=0.1)
    try:
        assert not session.direct  # nothing measured yet: the first frame is a draft
        assert shown_until(session, lambda: session.final)  # then the rested Quality result
        assert session.direct and engine.kinds() == [("fast", True), ("quality", False)]
        session.request(0.15)
        assert engine.count("fast") == 1  # no draft asked: the drag asks for the result itself
        assert shown_until(session, lambda: session.ratio == 0.15)
        assert_is_the_operators_result(ts, donut, session, 0.15, 6)
    finally:
        session.close()
    # a new session on the same (cached) mesh knows the measured time: no draft at all
    session = preview.PreviewSession(bpy.context, donut, params, ratio=0.12)
    try:
        calls = len(engine.calls)
        assert shown_until(session, lambda: session.ratio == 0.12 and session.final)
        assert engine.count("fast", draft=True) == 1 and len(engine.calls) > calls
        assert_is_the_operators_result(ts, donut, session, 0.12, 6)
    finally:
        session.close()


def test_a_slow_quality_result_leaves_the_drag_to_drafts(ts, donut, monkeypatch):
    preview = ts.blender.preview.session
    monkeypatch.setattr(preview, "SPECULATE", False)
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.draft)
    monkeypatch.setattr(preview, "DIRECT_SECONDS", 0.0)
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=7), ratio=0.1)
    try:
        assert shown_until(session, lambda: session.final) and not session.direct
        monkeypatch.setattr(preview, "REST_SECONDS", DAY)
        session.request(0.15)
        assert shown_until(session, lambda: session.ratio == 0.15)
        assert not session.final and engine.kinds()[-1] == ("fast", True)
    finally:
        session.close()


def test_a_ratio_rested_at_before_shows_its_kept_result_without_computing(ts, donut, monkeypatch):
    preview = ts.blender.preview.session
    engine = EngineCalls(monkeypatch, ts.blender.decimation.pipeline, hold=lambda job: job.draft)
    monkeypatch.setattr(preview, "DIRECT_SECONDS", 0.0)  # drafts while dragging
    session = preview.PreviewSession(bpy.context, donut, Params(quality="QUALITY", seed=8), ratio=0.1)
    try:
        assert shown_until(session, lambda: session.final)
        first = session.result
        session.request(0.2)
        assert shown_until(session, lambda: session.final and session.ratio == 0.2)
        assert wait_for(lambda: not session.busy)
        calls = len(engine.calls)
        session.request(0.1)  # back: a draft is asked, then the rest finds the kept result
        assert shown_until(session, lambda: session.final and session.ratio == 0.1)
        assert session.result is first and engine.count("quality") == 2
        assert engine.kinds(calls) in ([], [("fast", True)])  # at most the draft before the rest
        assert_is_the_operators_result(ts, donut, session, 0.1, 8)
    finally:
        session.close()
