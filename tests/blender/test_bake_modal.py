"""The operators' modal bake (operators/bake_run.py BakeModal): one step per timer event, the
progress in the cursor and the header, Esc cancels, leaving the scene as before the run. Blender
in background mode delivers no events: a stand-in operator gets the events an interactive
Blender would send (its timer and handler are the only parts replaced)."""

import importlib
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from helpers import snapshot
from test_bake_normals import decimated, small_pair, normal_map_image
from test_bake_undo import datablocks


@pytest.fixture
def bake_run(ts, monkeypatch):
    """bake_run with the ray cast in small chunks (Cycles' bake a no-op): many steps to take."""
    bake = importlib.import_module(f"{ts.__name__}.blender.decimation.bake")
    monkeypatch.setattr(bake, "_run_bake", lambda *args: None)
    monkeypatch.setattr(bake.bake_raycast, "CHUNK", 500)
    return importlib.import_module(f"{ts.__name__}.blender.operators.bake_run")


def stand_in(bake_run):
    """An operator with BakeModal whose Blender timer and handler are a token and nothing."""

    class Operator(bake_run.BakeModal):
        bake_size, bake_margin, bake_store, bake_colour = "64", 2, "PACK", False

        def __init__(self):
            self.reports, self.finished, self.cancelled = [], None, False

        def report(self, kind, message):
            self.reports.append((set(kind), message))

        def _listen(self, context):
            self._timer = object()

        def _stop_listening(self, context):
            self._timer = None

        def bake_finished(self, context, done):
            self.finished = done
            return {"FINISHED"}

        def bake_cancelled(self, context):
            self.cancelled = True
    return Operator()


def timer(operator):
    return SimpleNamespace(type="TIMER", timer=operator._timer)


def test_the_modal_bake_steps_on_timer_events(ts, bake_run, scene):
    source = small_pair()
    lods = [decimated(ts, source, f"lod{i}") for i in range(2)]
    operator = stand_in(bake_run)
    assert operator.start_bake(bpy.context, [(source, lod) for lod in lods], lods) == {"RUNNING_MODAL"}
    assert normal_map_image(lods[0]) is None                      # nothing baked before the first event
    other = SimpleNamespace(type="MOUSEMOVE", timer=None)
    assert operator.modal(bpy.context, other) == {"RUNNING_MODAL"} and operator._bake.fraction == 0.0
    fractions, answer = [], {"RUNNING_MODAL"}
    while answer == {"RUNNING_MODAL"}:
        answer = operator.modal(bpy.context, timer(operator))
        fractions.append(operator._bake.fraction)
    assert answer == {"FINISHED"} and operator._timer is None
    assert len(fractions) > 6 and fractions[-1] == 1.0 and np.all(np.diff(fractions) >= 0)
    assert any(0.2 < f < 0.5 for f in fractions) and any(0.5 < f < 1.0 for f in fractions)  # both LODs in steps
    lines, failures = operator.finished
    assert len(lines) == 2 and failures == []
    assert all(normal_map_image(lod) is not None for lod in lods)


@pytest.mark.parametrize("steps", [0, 3, 12])
def test_esc_leaves_the_scene_as_before(ts, bake_run, scene, steps):
    """Esc before the first step, in the first LOD's rays, or in the second's: the run's LODs
    and all their bakes made are removed, the source untouched."""
    source = small_pair()
    before = datablocks(), snapshot(source.data), [slot.material for slot in source.material_slots]
    lods = [decimated(ts, source, f"lod{i}") for i in range(2)]
    operator = stand_in(bake_run)
    operator.start_bake(bpy.context, [(source, lod) for lod in lods], lods)
    for _ in range(steps):
        assert operator.modal(bpy.context, timer(operator)) == {"RUNNING_MODAL"}
    assert operator.modal(bpy.context, SimpleNamespace(type="ESC", timer=None)) == {"CANCELLED"}
    assert operator.cancelled and operator.finished is None and operator._timer is None
    assert any("cancelled; nothing was changed" in message for _kind, message in operator.reports)
    assert (datablocks(), snapshot(source.data), [slot.material for slot in source.material_slots]) == before


def test_the_operators_bake_modal_only_with_events(ts, scene, monkeypatch):
    """Guided Decimate and the LOD chain take their modal from BakeModal (Guided Decimate's own
    modal, which also runs big decimations on a worker, hands a running bake's events to it);
    without events (Blender in background mode, as here) their invoke bakes at once."""
    bake_run = importlib.import_module(f"{ts.__name__}.blender.operators.bake_run")
    for operator in (bpy.types.TOPSTOC_OT_guided_decimate, bpy.types.TOPSTOC_OT_lod_chain):
        assert issubclass(operator, bake_run.BakeModal)
    assert bpy.types.TOPSTOC_OT_lod_chain.modal is bake_run.BakeModal.modal
    events = []
    monkeypatch.setattr(bake_run.BakeModal, "modal", lambda self, context, event: events.append(event) or {"PASS"})
    baking = SimpleNamespace(_bake=object())
    assert bpy.types.TOPSTOC_OT_guided_decimate.modal(baking, bpy.context, "an event") == {"PASS"}
    assert events == ["an event"]
    monkeypatch.undo()
    assert not bake_run.can_run_modal(bpy.context)
    source = small_pair()
    assert bpy.ops.topstoc.guided_decimate("INVOKE_DEFAULT", ratio=0.2, bake_normals=True,
                                           bake_size="256") == {"FINISHED"}
    assert normal_map_image(bpy.context.active_object) is not None
    assert normal_map_image(source) is None
