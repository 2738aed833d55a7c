"""Multiview (thesis 4.7.2) and LOD chains: several decimations laid out side by side."""

from __future__ import annotations

import bpy
import numpy as np
from mathutils import Vector

from ..decimation import pipeline
from ...core.support.errors import TopStocError
from ..props import OperatorBakeParameters, OperatorParameters, explicit_engine_options, fill_from_scene
from . import bake_run, polls


def parse_ratios(text: str) -> list:
    """'1, 0.5, 0.25' -> [1.0, 0.5, 0.25]; every ratio must lie in (0, 1]."""
    try:
        ratios = [float(part) for part in text.replace(";", ",").split(",") if part.strip()]
    except ValueError:
        raise pipeline.DecimationError(f"LOD ratios must be numbers separated by commas, got '{text}'") from None
    if not ratios or any(not 0 < r <= 1 for r in ratios):
        raise pipeline.DecimationError(f"LOD ratios must lie in (0, 1], got '{text}'")
    return ratios


def variant_ratios(ratio: float, count: int, variance: float) -> list:
    """``count`` ratios spread evenly over ratio * [1 - variance, 1 + variance] (capped at 1)."""
    spread = np.linspace(-1.0, 1.0, count) if count > 1 else np.zeros(1)
    return [float(min(1.0, max(1e-6, ratio * (1.0 + variance * t)))) for t in spread]


def _collection(context, name: str) -> bpy.types.Collection:
    collection = bpy.data.collections.get(name)
    if collection is None:
        collection = bpy.data.collections.new(name)
        context.scene.collection.children.link(collection)
    return collection


def _lay_out(source, objects, collection) -> None:
    """Moves the objects into ``collection``, side by side along X after the source."""
    corners = [source.matrix_world @ Vector(c) for c in source.bound_box]
    width = max(c.x for c in corners) - min(c.x for c in corners)
    step = 1.2 * width if width > 0 else 1.0
    for i, obj in enumerate(objects):
        for old in list(obj.users_collection):
            old.objects.unlink(obj)
        collection.objects.link(obj)
        obj.matrix_world = source.matrix_world.copy()
        obj.location.x += step * (i + 1)


class _VariantsBase(OperatorParameters, bake_run.BakeModal):
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.active_mesh_in_object_mode(context))

    def invoke(self, context, event):
        fill_from_scene(self, context.scene.topstoc)
        self._modal = bake_run.can_run_modal(context)  # a bake then runs modal: progress, Esc cancels
        return self.execute(context)

    def variants(self, context) -> list:
        raise NotImplementedError

    def names(self, obj, runs) -> list:
        raise NotImplementedError

    def execute(self, context):
        explicit_engine_options(self)
        obj = context.object
        try:
            runs = pipeline.decimate_many(context, obj, self, self.variants(context))
        except TopStocError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        names = self.names(obj, runs)
        outputs = [pipeline.write_output(run, "NEW_OBJECT", name=name, place=False) for run, name in zip(runs, names)]
        made_collection = bpy.data.collections.get(self.collection_name(obj)) is None
        collection = _collection(context, self.collection_name(obj))
        _lay_out(obj, outputs, collection)
        self._made = (obj, runs, outputs, collection if made_collection else None)
        if getattr(self, "bake_normals", False):
            pairs = [(obj, output) for output in outputs]
            if getattr(self, "_modal", False):
                return self.start_bake(context, pairs, outputs)
            done = bake_run.bake_or_discard(context, self, pairs, outputs)
            if done is None:
                self.bake_cancelled(context)
                self.report({"WARNING"}, "TopStoc: Bake Normals cancelled; nothing was changed")
                return {"CANCELLED"}
            return self.bake_finished(context, done)
        return self._report_runs()

    def bake_finished(self, context, done):
        baked, failures = done
        for line in baked:
            self.report({"INFO"}, f"TopStoc: {line}")
        for message in failures:
            self.report({"ERROR"}, message)
        return self._report_runs()

    def bake_cancelled(self, context) -> None:
        collection = self._made[3]
        if collection is not None:
            bpy.data.collections.remove(collection)

    def _report_runs(self):
        obj, runs, outputs, _collection = self._made
        counts = ", ".join(f"{run.result.num_vertices:,}" for run in runs)
        self.report({"INFO"}, f"TopStoc: {len(runs)} variants of {obj.name} ({counts} vertices) "
                              f"in {runs[0].seconds:.3f} s")
        for run, output in zip(runs, outputs):
            missed = run.result.stats.target_missed
            if missed is not None:
                self.report({"WARNING"}, f"TopStoc: {output.name}: {missed.text()}")
            if run.result.stats.topology_warning:
                self.report({"WARNING"}, f"TopStoc: {output.name}: {run.result.stats.topology_warning}")
        return {"FINISHED"}


class TOPSTOC_OT_multiview(_VariantsBase, bpy.types.Operator):
    """Several decimations with different seeds and ±variance on the ratio, side by side"""

    bl_idname = "topstoc.multiview"
    bl_label = "Multiview"

    count: bpy.props.IntProperty(name="Variants", default=4, min=1, max=32)
    variance: bpy.props.FloatProperty(name="Variance", default=0.25, min=0.0, max=0.95, subtype="FACTOR")

    def invoke(self, context, event):
        if not self.properties.is_property_set("count"):
            self.count = context.scene.topstoc.variants
        if not self.properties.is_property_set("variance"):
            self.variance = context.scene.topstoc.variance
        return super().invoke(context, event)

    def variants(self, context):
        return [({"ratio": r}, self.seed + i) for i, r in enumerate(variant_ratios(self.ratio, self.count,
                                                                                     self.variance))]

    def names(self, obj, runs):
        return [f"{obj.name}_MV{i + 1}" for i in range(len(runs))]

    def collection_name(self, obj):
        return f"{obj.name} Multiview"


class TOPSTOC_OT_lod_chain(_VariantsBase, OperatorBakeParameters, bpy.types.Operator):
    """LOD0 ... LODn at the given ratios, named and collected"""

    bl_idname = "topstoc.lod_chain"
    bl_label = "LOD Chain"

    ratios: bpy.props.StringProperty(name="Ratios", default="1.0, 0.5, 0.25, 0.1")

    def invoke(self, context, event):
        if not self.properties.is_property_set("ratios"):
            self.ratios = context.scene.topstoc.lod_ratios
        return super().invoke(context, event)

    def variants(self, context):
        return [({"ratio": r}, self.seed) for r in parse_ratios(self.ratios)]

    def names(self, obj, runs):
        return [f"{obj.name}_LOD{i}" for i in range(len(runs))]

    def collection_name(self, obj):
        return f"{obj.name} LODs"


CLASSES = (TOPSTOC_OT_multiview, TOPSTOC_OT_lod_chain)
