"""One guided decimation of a Blender object: prepare (cached), gather guidance, decimate,
write the output, remember the samples. Shared by the operators, the preview and the batch."""

from __future__ import annotations

import hashlib
import inspect
import json
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import bpy
import numpy as np

from ..core.decimate import decimate as decimate_function
from . import mesh_io
from .cache import Prepared, prepared_meshes
from .guidance import EngineGuidance, gather

LAST_SAMPLES = "Last"


class DecimationError(ValueError):
    """A decimation that cannot run (message for the status bar / batch log)."""


@dataclass
class Run:
    """A finished decimation of one object."""

    obj: bpy.types.Object
    prepared: Prepared
    guidance: EngineGuidance
    result: object            #: topstoc.core.DecimateResult
    parameters: dict          #: what reproduces it (target, seed, options)
    seconds: float            #: read + prepare + decimate


def has_max_error() -> bool:
    """True when the engine offers the max-deviation target (Hausdorff issue)."""
    return "max_error" in inspect.signature(decimate_function).parameters


def target_kwargs(params, prepared: Prepared) -> dict:
    """The engine target for a DecimationParameters holder."""
    mode = params.target_mode
    if mode == "RATIO":
        return {"ratio": float(params.ratio)}
    if mode == "VERTICES":
        return {"vertices": int(params.vertices)}
    if mode == "TRIANGLES":
        return {"triangles": int(params.triangles)}
    if not has_max_error():
        raise DecimationError("the max-deviation target needs the Hausdorff engine, which this build lacks")
    if params.max_error_relative:  # the panel says percent; the engine takes a fraction of the diagonal
        return {"max_error": float(params.max_error) / 100.0, "relative": True}
    return {"max_error": float(params.max_error)}


def options_kwargs(params) -> dict:
    """Engine options for a DecimationParameters holder. Quality mode (the default) uses the
    engine's quality settings; Fast mode the holder's placement and refinement (by default
    the thesis' plain TopStoc)."""
    mode = str(getattr(params, "quality_mode", "QUALITY")).lower()
    options = dict(seed=int(params.seed), adaptivity=float(params.adaptivity), density=params.density, mode=mode)
    if mode == "fast":
        options.update(placement=params.placement or None,
                       refine=None if params.refine is None else float(params.refine))
    return options


def check_mesh(obj) -> None:
    if obj is None or obj.type != "MESH":
        raise DecimationError(f"'{getattr(obj, 'name', obj)}' is not a mesh object")
    if obj.mode == "EDIT":
        raise DecimationError(f"'{obj.name}' is in Edit Mode; switch to Object Mode")


def prepare(obj) -> Prepared:
    """The cached prepared mesh of ``obj``, with a clear error for unusable meshes."""
    check_mesh(obj)
    if len(obj.data.polygons) == 0:
        raise DecimationError(f"'{obj.name}' has no faces to decimate")
    try:
        prepared = prepared_meshes.get(obj.data)
    except ValueError as error:
        raise DecimationError(f"'{obj.name}': {error}") from None
    if prepared.mesh.num_triangles == 0:
        raise DecimationError(f"'{obj.name}' has only degenerate faces")
    return prepared


def decimate(context, obj, params, *, seed_offset: int = 0, target: dict = None, region_3d=None) -> Run:
    """Decimates ``obj`` with the scene's guidance settings and ``params`` (nothing written)."""
    start = time.perf_counter()
    prepared = prepare(obj)
    guidance = gather(obj, prepared.arrays, context.scene, None, region_3d)
    target = target if target is not None else target_kwargs(params, prepared)
    options = options_kwargs(params)
    options["seed"] += seed_offset
    try:
        result = prepared.mesh.decimate(**target, **options, **guidance.decimate_kwargs())
    except ValueError as error:
        raise DecimationError(f"'{obj.name}': {error}") from None
    parameters = dict(target, **options, sources=guidance.sources)
    return Run(obj, prepared, guidance, result, parameters, time.perf_counter() - start)


def _link_like(source, new) -> None:
    collections = source.users_collection or (bpy.context.scene.collection,)
    for collection in collections:
        collection.objects.link(new)
    new.parent = source.parent
    new.matrix_parent_inverse = source.matrix_parent_inverse.copy()
    new.matrix_world = source.matrix_world.copy()


def _object_materials(source, new) -> None:
    for index, slot in enumerate(source.material_slots):
        if slot.link == "OBJECT" and index < len(new.material_slots):
            new.material_slots[index].link = "OBJECT"
            new.material_slots[index].material = slot.material


def write_output(run: Run, mode: str = "NEW_OBJECT", name: str = None) -> bpy.types.Object:
    """Writes a Run as a new object (default) or into the object itself; returns the object."""
    obj = run.obj
    groups = mesh_io.collect_vertex_groups(obj, np.asarray(run.result.kept))
    if mode == "IN_PLACE":
        old = obj.data
        mesh = mesh_io.build_result_mesh(old, run.prepared.arrays, run.result, old.name + "_TopStoc")
        old_name = old.name
        obj.data = mesh
        if old.users == 0:
            bpy.data.meshes.remove(old)
        mesh.name = old_name
        target = obj
    else:
        name = name or f"{obj.name}_TopStoc"
        mesh = mesh_io.build_result_mesh(obj.data, run.prepared.arrays, run.result, name)
        target = bpy.data.objects.new(name, mesh)
        _link_like(obj, target)
        _object_materials(obj, target)
    mesh_io.apply_vertex_groups(target, groups)
    target["topstoc_source"] = obj.name
    target["topstoc_parameters"] = json.dumps(run.parameters)
    return target


def guidance_digest(guidance) -> str:
    """Fingerprint of a per-vertex guidance array (None: no guidance)."""
    if guidance is None:
        return "-"
    return hashlib.blake2b(np.ascontiguousarray(guidance, dtype=np.float64).tobytes(), digest_size=16).hexdigest()


def store_samples(run: Run, name: str = LAST_SAMPLES) -> None:
    """Remembers the run's samples on its object (replacing a set of the same name)."""
    sets = run.obj.topstoc.sample_sets
    entry = sets.get(name)
    if entry is None:
        entry = sets.add()
        entry.name = name
    # A refined result replays with its refinement target and the same per-vertex guidance.
    entry.parameters = json.dumps(dict(run.parameters, refine_vertices=int(run.result.stats.refine_vertices),
                                       placement=run.result.parameters.get("placement", "subsample"),
                                       guidance_digest=guidance_digest(run.guidance.guidance)))
    entry.mesh_digest = run.prepared.digest
    entry.layout_digest = run.guidance.layout_digest()
    entry.vertices_out = run.result.num_vertices
    entry.triangles_out = run.result.num_triangles
    entry["samples"] = np.asarray(run.result.samples, dtype=np.int32).tolist()


def restore(context, obj, name: str) -> Run:
    """Re-creates a stored decimation exactly; refuses when the mesh or its borders changed."""
    entry = obj.topstoc.sample_sets.get(name)
    if entry is None or "samples" not in entry:
        raise DecimationError(f"'{obj.name}' has no saved samples named '{name}'")
    start = time.perf_counter()
    prepared = prepare(obj)
    if prepared.digest != entry.mesh_digest:
        raise DecimationError(f"'{obj.name}' changed since the samples '{name}' were saved")
    guidance = gather(obj, prepared.arrays, context.scene)
    if guidance.layout_digest() != entry.layout_digest:
        raise DecimationError(f"the seams, sharp edges or materials of '{obj.name}' changed since "
                              f"the samples '{name}' were saved")
    parameters = json.loads(entry.parameters)
    refine_vertices = int(parameters.get("refine_vertices", 0))
    if refine_vertices and parameters.get("guidance_digest") != guidance_digest(guidance.guidance):
        raise DecimationError(f"the painted guidance of '{obj.name}' changed since the refined samples "
                              f"'{name}' were saved")
    samples = np.asarray(entry["samples"], dtype=np.int32)
    result = prepared.mesh.decimate_with_samples(samples, placement=parameters.get("placement", "subsample"),
                                                 refine_vertices=refine_vertices,
                                                 guidance=guidance.guidance if refine_vertices else None,
                                                 **guidance.layout_kwargs())
    return Run(obj, prepared, guidance, result, parameters, time.perf_counter() - start)


def summary(run: Run, seconds: float = None) -> str:
    """One status-bar line: counts and time."""
    report = run.prepared.mesh.report()
    seconds = run.seconds if seconds is None else seconds
    text = (f"{run.obj.name}: {report.input_vertices:,} -> {run.result.num_vertices:,} vertices, "
            f"{run.result.num_triangles:,} triangles in {seconds:.3f} s")
    bound = getattr(run.result, "error_bound", None)
    if bound is not None:
        text += f", deviation {bound.achieved_error:.4g} <= {bound.max_error:.4g}"
    if run.result.stats.repairs:
        text += f" ({run.result.stats.repairs} topology repairs)"
    over = getattr(run.result.stats, "over_budget", 0)
    if over:
        text += f", {over:,} vertices over the target ({run.result.stats.over_budget_reason})"
    return text


def decimate_many(context, obj, params, variants) -> list:
    """Several decimations of one object in parallel (the engine releases the GIL).

    variants: (target kwargs, seed) pairs. Returns one Run per variant, in order.
    """
    start = time.perf_counter()
    prepared = prepare(obj)
    guidance = gather(obj, prepared.arrays, context.scene)
    prepared.mesh.feature_layout(guidance.regions, guidance.borders)  # built once, shared by the threads
    options = options_kwargs(params)

    def one(target, seed):
        return prepared.mesh.decimate(**target, **dict(options, seed=seed), **guidance.decimate_kwargs())

    try:
        with ThreadPoolExecutor(max_workers=max(1, min(len(variants), os.cpu_count() or 1))) as pool:
            results = list(pool.map(lambda v: one(*v), variants))
    except ValueError as error:
        raise DecimationError(f"'{obj.name}': {error}") from None
    seconds = time.perf_counter() - start
    return [Run(obj, prepared, guidance, result, dict(target, **dict(options, seed=seed), sources=guidance.sources),
                seconds) for (target, seed), result in zip(variants, results)]
