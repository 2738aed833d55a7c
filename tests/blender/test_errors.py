"""The add-on's errors share one base (TopStocError, a ValueError) and the three entry points
(decimation, analysis, metrics) refuse an unusable object with the same words."""

import importlib

import bpy
import pytest

import meshgen
from helpers import Params, make_object

ERRORS = [("decimation.pipeline", "DecimationError"), ("decimation.guidance", "GuidanceError"),
          ("analysis.topology", "AnalysisError"), ("io.mesh_edit", "EditError"), ("analysis.metrics", "MetricsError")]


def test_every_error_derives_from_topstoc_error(ts):
    base = ts.core.TopStocError
    assert issubclass(base, ValueError)
    for module, name in ERRORS:
        error = getattr(importlib.import_module(f"{ts.__name__}.blender.{module}"), name)
        assert issubclass(error, base) and error is not base, name


def _refusals(ts, obj):
    """What each entry point raises for ``obj``: (error class, message)."""
    analysis = importlib.import_module(ts.__name__ + ".blender.analysis.topology")
    metrics = importlib.import_module(ts.__name__ + ".blender.analysis.metrics")
    pipeline = ts.blender.decimation.pipeline
    calls = [(pipeline.DecimationError, lambda: pipeline.decimate(bpy.context, obj, Params())),
             (analysis.AnalysisError, lambda: analysis.analyse(obj)),
             (metrics.MetricsError, lambda: metrics.measure(obj, reference=obj))]
    found = []
    for expected, call in calls:
        with pytest.raises(expected) as caught:
            call()
        found.append(str(caught.value))
    return found


def test_not_a_mesh_refused_alike(ts, scene):
    empty = bpy.data.objects.new("Handle", None)
    scene.collection.objects.link(empty)
    assert _refusals(ts, empty) == ["'Handle' is not a mesh object"] * 3


def test_edit_mode_refused_alike(ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(2))
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        assert _refusals(ts, obj) == ["'Ball' is in Edit Mode; switch to Object Mode"] * 3
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
