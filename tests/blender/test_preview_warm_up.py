"""Live Preview warm-ups (preview/warm_up.py): an idle worker builds what the rested Quality result
resumes from (the first collapse run's state and the input's search structure) toward a little
above the highest ratio the drag asks (warm_up.HEADROOM). The rest then resumes from it and makes no search structure, with the result a
decimation of a mesh that keeps nothing gives, bit for bit; a rest above a running warm-up, or
the session closing, cancels it in the engine.

The rests are asked for explicitly (REST_SECONDS a day, no speculation); no wall time is asserted."""

import threading

import bpy
import numpy as np
import pytest

import meshgen
from helpers import Params, make_object, wait_for

DAY = 86400.0


@pytest.fixture
def torus(ts, scene):
    ts.blender.preview.cache.prepared_meshes.clear()
    vertices, triangles = meshgen.bumpy_torus(20000)  # collapsed whole, in batches
    return make_object("Torus", vertices, triangles)


@pytest.fixture
def preview(ts, monkeypatch):
    module = ts.blender.preview.session
    monkeypatch.setattr(module, "DIRECT_SECONDS", 0.0)  # Quality counts as slow: the drag shows drafts
    monkeypatch.setattr(module, "REST_SECONDS", DAY)
    monkeypatch.setattr(module, "SPECULATE", False)
    return module


def kept_states(ts, session, ratio):
    """The collapse states the session's decimations at ``ratio`` use (Mesh.kept_for_reuse)."""
    mesh = session.prepared.mesh
    job = ts.blender.decimation.pipeline.engine_job(mesh, {"ratio": ratio}, session.options, session.guidance)
    return mesh.kept_for_reuse(job.regions, job.borders, job.feature_angle)[2]


def rest(session, ratio):
    session.request(ratio, final=True)
    assert wait_for(lambda: (session.poll(), session.final and session.ratio == ratio)[1])
    return session.result


def assert_is_a_plain_decimation(ts, session, result, ratio):
    """``result`` is what a mesh that keeps nothing between decimations gives (core.api)."""
    arrays = session.prepared.arrays
    plain = ts.core.Mesh(arrays.vertices, arrays.triangles, keep_floods=False)
    pipeline = ts.blender.decimation.pipeline
    expected = pipeline.run_engine(plain, pipeline.engine_job(plain, {"ratio": ratio}, session.options,
                                                              session.guidance))
    for name in ("vertices", "triangles", "kept", "samples", "corner_source"):
        np.testing.assert_array_equal(np.asarray(getattr(result, name)), np.asarray(getattr(expected, name)),
                                      err_msg=name)


def test_the_rest_resumes_from_the_warm_up_of_the_drag(ts, torus, preview):
    session = preview.PreviewSession(bpy.context, torus, Params(quality="QUALITY", seed=3), ratio=0.1)
    try:
        assert wait_for(lambda: (session.poll(), session.warm_ups.finished >= 1)[1])  # at the start
        states = kept_states(ts, session, 0.1)
        assert (states.size, states.surfaces_made, states.resumed) == (1, 1, 0)
        session.request(0.05)  # the drag goes on below: served by the same state
        result = rest(session, 0.05)
        assert (states.resumed, states.surfaces_made) == (1, 1)  # nothing rebuilt by the rest
        assert_is_a_plain_decimation(ts, session, result, 0.05)
        result = rest(session, 0.08)
        assert (states.resumed, states.surfaces_made, session.warm_ups.finished) == (2, 1, 1)
        assert_is_a_plain_decimation(ts, session, result, 0.08)
    finally:
        session.close()


def held_warm_ups(preview, monkeypatch):
    """Holds every warm-up at a gate before the engine; returns the gate and the flags seen."""
    gate, flags, real = threading.Event(), [], preview.warm_up

    def held(mesh, job, cancel=None):
        flags.append(cancel)
        gate.wait(30)
        return real(mesh, job, cancel)

    monkeypatch.setattr(preview, "warm_up", held)
    return gate, flags


def test_a_rest_above_a_running_warm_up_cancels_it(ts, torus, preview, monkeypatch):
    gate, flags = held_warm_ups(preview, monkeypatch)
    session = preview.PreviewSession(bpy.context, torus, Params(quality="QUALITY", seed=3), ratio=0.05)
    try:
        assert wait_for(lambda: (session.poll(), session.warm_ups.running == pytest.approx(0.05 * 1.15))[1])
        session.request(0.1, final=True)  # the drag came back up and rests there
        assert wait_for(lambda: flags[0].is_set)
        gate.set()  # the held warm-up reaches the engine with its flag set: Cancelled
        result = rest(session, 0.1)
        assert_is_a_plain_decimation(ts, session, result, 0.1)
        assert session.warm_ups.finished == 0
    finally:
        gate.set()
        session.close()


def test_closing_cancels_the_warm_up_and_a_changed_mesh_starts_anew(ts, torus, preview, monkeypatch):
    gate, flags = held_warm_ups(preview, monkeypatch)
    session = preview.PreviewSession(bpy.context, torus, Params(quality="QUALITY", seed=3), ratio=0.1)
    assert wait_for(lambda: (session.poll(), session.warm_ups.running == pytest.approx(0.1 * 1.15))[1])
    states = kept_states(ts, session, 0.1)
    session.close()
    assert flags[0].is_set
    gate.set()
    assert wait_for(lambda: session.warm_ups.running is None)
    assert (states.size, states.surfaces_made) == (0, 0)
    torus.data.vertices[0].co.z += 0.01  # another mesh: prepared again, its own states
    session = preview.PreviewSession(bpy.context, torus, Params(quality="QUALITY", seed=3), ratio=0.1)
    try:
        assert wait_for(lambda: (session.poll(), session.warm_ups.finished >= 1)[1])
        fresh = kept_states(ts, session, 0.1)
        assert fresh is not states and (fresh.size, fresh.resumed) == (1, 0)
        result = rest(session, 0.1)
        assert fresh.resumed == 1
        assert_is_a_plain_decimation(ts, session, result, 0.1)
    finally:
        session.close()


def test_the_warm_ups_go_above_the_highest_ratio_asked(ts):
    """One warm-up serves a drag up and down below the highest ratio asked (a warm-up toward each
    ratio of an upward sweep would start from nothing every time); a drag beyond it gets a new
    one. Where a warm-up keeps nothing (guidance, fast mode, a first pass that grows with the
    ratio) none is tried again near that ratio; one that fails, never again."""
    warmed = []
    warm_ups = ts.blender.preview.warm_up.WarmUps(lambda ratio, cancel: warmed.append(ratio) or True)

    def step(highest):
        ratio = warm_ups.next(highest)
        if ratio is not None:
            warm_ups.run(ratio)
        return ratio

    assert step(0.1) == pytest.approx(0.115)
    assert all(step(0.1) is None for _ in range(20))
    warm_ups.made(0.05)  # a rest below
    assert step(0.11) is None  # the state made toward 0.115 serves it
    assert step(0.2) == pytest.approx(0.23)
    assert step(0.95) == 1.0
    assert warmed == pytest.approx([0.115, 0.23, 1.0]) and warm_ups.finished == 3
    tried = []
    nothing = ts.blender.preview.warm_up.WarmUps(lambda ratio, cancel: tried.append(ratio) or False)
    nothing.run(nothing.next(0.1))
    assert nothing.next(0.1) is None and nothing.next(0.09) is None  # near 0.115: not again
    nothing.run(nothing.next(0.2))
    assert tried == pytest.approx([0.115, 0.23]) and nothing.applies and nothing.finished == 2

    def failing(ratio, cancel):
        raise RuntimeError("the engine failed")
    broken = ts.blender.preview.warm_up.WarmUps(failing)
    broken.run(broken.next(0.1))
    assert broken.next(0.2) is None and not broken.applies
