"""The ray-cast bake (bake_raycast.py, where Cycles bakes nothing) reports its progress in chunks
and can be cancelled through its progress callback: the map it makes does not depend on the chunks,
a cancelled bake leaves the LOD as it was, and a cancelled Guided Decimate or LOD chain leaves the
scene as before the run (the operators' callback is replaced by one that cancels: the tests' hook)."""

import importlib
import os

import bpy
import numpy as np
import pytest

from helpers import select_only, snapshot
from test_bake_normals import decimated, small_pair
from test_bake_undo import datablocks


@pytest.fixture
def bake(ts, monkeypatch):
    """The bake module with Cycles' bake a no-op (so the ray cast runs in every Blender) and small chunks."""
    module = importlib.import_module(f"{ts.__name__}.blender.decimation.bake")
    monkeypatch.setattr(module, "_run_bake", lambda *args: None)
    monkeypatch.setattr(module.bake_raycast, "CHUNK", 200)
    return module


def pixels(image):
    out = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(out)
    return out


def canceller(after):
    """A progress callback that lets ``after`` reports through, then cancels; records the fractions."""
    told = []

    def progress(fraction):
        told.append(fraction)
        return len(told) <= after
    return progress, told


def test_progress_in_chunks_and_the_same_map(ts, bake, scene, monkeypatch):
    source = small_pair()
    lods = [decimated(ts, source, f"lod{i}") for i in range(2)]
    told = []
    chunked = bake.bake_normals(bpy.context, source, lods[0], size=64, margin=2, progress=told.append)
    monkeypatch.setattr(bake.bake_raycast, "CHUNK", 10 ** 9)
    whole = bake.bake_normals(bpy.context, source, lods[1], size=64, margin=2)
    assert chunked.method == whole.method == "ray cast"
    # 0 when ready to bake and when Cycles' turn is done, one report per chunk of 200 rays, 1 when stored
    assert told[:2] == [0.0, 0.0] and told[-1] == 1.0
    chunks = told[2:-1]
    steps = np.diff(chunks)
    assert len(chunks) > 2 and chunks[-1] == 1.0
    assert np.allclose(steps[:-1], chunks[0]) and 0 < steps[-1] <= chunks[0] + 1e-12
    assert np.array_equal(pixels(chunked.image), pixels(whole.image))


def test_a_cancelled_bake_leaves_the_lod_as_it_was(ts, bake, scene):
    source = small_pair()
    lod = decimated(ts, source, "lod")
    before = datablocks(), snapshot(lod.data), [slot.material for slot in lod.material_slots]
    progress, told = canceller(after=2)
    with pytest.raises(bake.bake_raycast.Cancelled, match="cancelled"):
        bake.bake_normals(bpy.context, source, lod, size=64, margin=2, progress=progress)
    assert len(told) == 3 and told[-1] < 1.0
    assert (datablocks(), snapshot(lod.data), [slot.material for slot in lod.material_slots]) == before


RUNS = {"guided_decimate": {"ratio": 0.2}, "lod_chain": {"ratios": "1.0, 0.2"}}


@pytest.mark.parametrize("operator, store", [(name, "PACK") for name in sorted(RUNS)] + [("guided_decimate", "FILE")])
def test_a_cancelled_operator_leaves_the_scene_as_before(ts, bake, scene, tmp_path, monkeypatch, operator, store):
    """Saved beside the .blend (store FILE), the maps already written are removed too."""
    monkeypatch.setattr(bake, "bake_folder", lambda: str(tmp_path))
    (tmp_path / "a_TopStoc_normal.png").write_bytes(b"the user's file")  # taken: the bake writes _1
    sources = [small_pair("a"), small_pair("b")]
    select_only(sources[0])
    if operator == "guided_decimate":                             # two sources: the first one's bake is undone too
        sources[1].select_set(True)
    bake_run = importlib.import_module(f"{ts.__name__}.blender.operators.bake_run")
    calls = []

    def cancelling(context):
        progress, told = canceller(after=1_000_000)
        calls.append(told)
        return lambda fraction: progress(fraction) and fraction < 0.75   # cancels the last bake midway
    monkeypatch.setattr(bake_run, "cursor_progress", cancelling)
    selected = sorted(o.name for o in bpy.context.selected_objects)
    before = datablocks(), [snapshot(s.data) for s in sources]
    assert getattr(bpy.ops.topstoc, operator)(bake_normals=True, bake_size="256", bake_margin=2, bake_store=store,
                                              **RUNS[operator]) == {"CANCELLED"}
    assert calls and calls[0][0] < 0.75 <= calls[0][-1]          # the run got that far before cancelling
    assert (datablocks(), [snapshot(s.data) for s in sources]) == before
    assert sorted(o.name for o in bpy.context.selected_objects) == selected
    assert os.listdir(tmp_path) == ["a_TopStoc_normal.png"]
    assert (tmp_path / "a_TopStoc_normal.png").read_bytes() == b"the user's file"
