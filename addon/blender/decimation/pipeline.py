"""One guided decimation of a Blender object: prepare (cached), gather guidance, decimate,
write the output, remember the samples. Shared by the operators, the preview and the batch.

Every front end (Guided Decimate, Live Preview, LOD chain, Regenerate, the Blender batch) goes
through ``engine_job``, the one adapter from the add-on to a core DecimationJob. Names here:
``panel`` is a holder of the DecimationParameters values (an operator, the scene's settings, a
namespace); ``options`` the make_job keywords its values give (decimate_options); ``settings``
the panel's values as JSON (what Regenerate re-runs); ``parameters`` the record of what a
result ran with (stored on the result object and with its samples).
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Optional

import bpy
import numpy as np

from ...core.carry.appearance import refines
from ...core.carry.attributes import MovedVertices, moved_vertices_of, point_weights
from ...core.api.decimate import run_job
from ...core.support.errors import TopStocError
from ...core.api.job import ATTRIBUTE_WEIGHT, DecimationJob, make_job
from ..io import mesh_read, mesh_write, mesh_attributes, carry
from ..preview.cache import Prepared, prepared_meshes
from .guidance import EngineGuidance, appearance_color, gather, guidance_layers, read as read_guidance

LAST_SAMPLES = "Last"


class DecimationError(TopStocError):
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
    settings: dict = None     #: the panel settings it ran with (Regenerate re-runs them)
    moved: MovedVertices = None  #: where moved vertices take their attributes (found when written if None)


def settings_of(panel) -> dict:
    """The DecimationParameters values of a panel, as plain JSON-able values."""
    from ..props import DecimationParameters

    return {name: getattr(panel, name) for name in DecimationParameters.__annotations__ if hasattr(panel, name)}


def target_kwargs(panel) -> dict:
    """The decimation target of a panel (make_job's target keywords)."""
    mode = panel.target_mode
    if mode == "RATIO":
        return {"ratio": float(panel.ratio)}
    if mode == "VERTICES":
        return {"target_vertices": int(panel.vertices)}
    if mode == "TRIANGLES":
        return {"target_triangles": int(panel.triangles)}
    if panel.max_error_relative:  # the panel says percent; the engine takes a fraction of the diagonal
        return {"max_error": float(panel.max_error) / 100.0, "relative": True}
    return {"max_error": float(panel.max_error)}


#: the engine mode behind the panel's Quality choice (Custom: the Advanced placement and refinement)
QUALITY_MODES = {"QUALITY": "quality", "BEST": "best", "FAST": "fast"}


def decimate_options(panel) -> dict:
    """make_job's keywords for a panel: seed, adaptivity, density, the mode its Quality choice
    picks (Custom, or a holder without the choice as the batch's: placement and refinement
    themselves, on the holder's mode, fast unless it says otherwise), the mirror axis when
    symmetry is on, and ``attribute_weight``, the look's weight (engine_job makes it attributes)."""
    options = dict(seed=int(panel.seed), adaptivity=float(panel.adaptivity), density=panel.density,
                   attribute_weight=float(getattr(panel, "attribute_weight", ATTRIBUTE_WEIGHT)),
                   symmetry=panel.symmetry_axis if getattr(panel, "use_symmetry", False) else None)
    mode = QUALITY_MODES.get(getattr(panel, "quality", "CUSTOM"))
    if mode is not None:
        options.update(mode=mode)
    else:
        options.update(mode=getattr(panel, "mode", None) or "fast", placement=panel.placement or None,
                       refine=None if panel.refine is None else float(panel.refine))
    return options


def look_kwargs(options: dict, appearance) -> dict:
    """The engine's ``attributes`` for ``options``: the look (``appearance``, a function giving
    core.carry.appearance.Appearance) at the options' ``attribute_weight`` when the refinement runs
    (the only stage that uses it), else nothing."""
    weight = options.get("attribute_weight", ATTRIBUTE_WEIGHT)
    if appearance is None or weight == 0 or not refines(options.get("mode", "quality"), options.get("refine")):
        return {}
    return appearance().decimate_kwargs(weight)


def engine_job(mesh, target: dict, options: dict, guidance: EngineGuidance) -> DecimationJob:
    """The one adapter from the add-on to the engine: the DecimationJob (core/api/job.py) of a
    target, a panel's options (decimate_options) and the guidance gathered from the scene."""
    choices = {name: value for name, value in options.items() if name != "attribute_weight"}
    return make_job(mesh, **target, **choices, guidance=guidance.guidance, regions=guidance.regions,
                    borders=guidance.borders, view=guidance.view, boxes=guidance.boxes,
                    **look_kwargs(options, guidance.appearance))


def run_engine(mesh, job: DecimationJob, progress=None, cancel=None):
    """One engine decimation of a job (every add-on decimation passes here); progress: an error
    target's search, cancel: a CancelFlag that stops it (core.api.decimate.run_job)."""
    return run_job(mesh, job, progress, cancel)


def input_triangles(mesh) -> int:
    """Triangles of a Blender mesh after triangulation (each n-gon gives n - 2)."""
    return max(0, len(mesh.loops) - 2 * len(mesh.polygons))


def face_estimate(panel, mesh):
    """The output's triangle count the target will give, estimated without decimating (like
    the Decimate modifier's Face Count): a triangulated surface has about two triangles per
    vertex, so the count scales with the kept vertices. None for a max-deviation target."""
    triangles, vertices = input_triangles(mesh), len(mesh.vertices)
    if triangles == 0 or vertices == 0:
        return 0
    mode = panel.target_mode
    if mode == "TRIANGLES":
        return min(int(panel.triangles), triangles)
    if mode == "RATIO":
        kept = panel.ratio * vertices
    elif mode == "VERTICES":
        kept = min(int(panel.vertices), vertices)
    else:
        return None
    return max(1, int(round(triangles * kept / vertices)))


def check_decimatable(obj) -> None:
    """Raises DecimationError unless ``obj`` is a mesh object with faces, in Object Mode."""
    mesh_read.check_mesh_object(obj, DecimationError)
    if len(obj.data.polygons) == 0:
        raise DecimationError(f"'{obj.name}' has no faces to decimate")


def prepare(obj) -> Prepared:
    """The cached prepared mesh of ``obj``, with a clear error for unusable meshes."""
    check_decimatable(obj)
    return prepare_arrays(obj.name, obj.data.name_full, mesh_read.read_mesh(obj.data))


def prepare_arrays(obj_name: str, mesh_name: str, arrays: mesh_read.MeshArrays, progress=None) -> Prepared:
    """``prepare`` for arrays already read (any thread: no Blender data is touched); progress:
    see :class:`topstoc.core.Mesh` (its False raises ``Cancelled``)."""
    try:
        prepared = prepared_meshes.prepare(mesh_name, arrays, progress)
    except ValueError as error:
        raise DecimationError(f"'{obj_name}': {error}") from None
    if prepared.mesh.num_triangles == 0:
        raise DecimationError(f"'{obj_name}' has only degenerate faces")
    return prepared


def decimate(context, obj, panel, *, target: dict = None, region_3d=None) -> Run:
    """Decimates ``obj`` with the scene's guidance and a panel's settings (nothing written);
    ``target`` replaces the panel's."""
    return decimate_read(read_input(context, obj, panel, target=target, region_3d=region_3d))


@dataclass
class Input:
    """What one decimation of an object needs from Blender, read on the main thread."""

    obj: bpy.types.Object
    arrays: mesh_read.MeshArrays
    read_guidance: object     #: guidance.read's function: the engine guidance (any thread)
    target: dict
    options: dict
    settings: dict
    started: float            #: when the read began (a Run's seconds count from it)


def read_input(context, obj, panel, *, target: dict = None, region_3d=None) -> Input:
    """Reads ``obj``'s mesh, guidance sources and a panel's settings (main thread: Blender data);
    ``target`` replaces the panel's. Unusable meshes and guidance raise here."""
    started = time.perf_counter()
    check_decimatable(obj)
    arrays = mesh_read.read_mesh(obj.data)
    reader = read_guidance(obj, arrays, context.scene, None, region_3d)
    return Input(obj, arrays, reader, target if target is not None else target_kwargs(panel),
                 decimate_options(panel), settings_of(panel), started)


def decimate_read(read: Input, prepare_progress=None, progress=None, cancel=None, one_shot: bool = False) -> Run:
    """Prepares (cached) and decimates what ``read_input`` read; reads no Blender data (any thread).
    prepare_progress: the preparation's ``(fraction, stage)``, progress: an error target's search
    ``(probe, target, vertices, error, passed)``; either returning False raises ``Cancelled``, as
    does ``cancel`` (a CancelFlag) once set, in the decimation.
    one_shot (a big job on the worker): the read's positions and triangles are handed to the
    prepared mesh (MeshArrays.hand_over) and its layouts freed after, so that neither is kept
    beside the engine's working set; the result is the same."""
    obj_name = read.obj.name
    prepared = prepare_arrays(obj_name, read.obj.data.name_full, read.arrays, prepare_progress)
    if one_shot:
        read.arrays.hand_over(prepared.mesh)
    if prepare_progress is not None:  # also when the cache held it: the decimation starts
        prepare_progress(1.0, "prepared")
    guidance = read.read_guidance()
    try:
        job = engine_job(prepared.mesh, read.target, read.options, guidance)
        result = (run_engine(prepared.mesh, job) if progress is None and cancel is None
                  else run_engine(prepared.mesh, job, progress, cancel))
    except ValueError as error:
        raise DecimationError(f"'{obj_name}': {error}") from None
    if one_shot:
        prepared.mesh.clear_layouts()
    return make_run(read.obj, prepared, guidance, result, read.target, read.options,
                    time.perf_counter() - read.started, read.settings)


def make_run(obj, prepared: Prepared, guidance: EngineGuidance, result, target: dict, options: dict,
             seconds: float, settings: dict, moved: MovedVertices = None) -> Run:
    """The Run of a finished engine decimation of ``target`` with ``options`` (decimate_options')."""
    return Run(obj, prepared, guidance, result, record(target, options, guidance, result), seconds, settings, moved)


def record(target: dict, options: dict, guidance: EngineGuidance, result) -> dict:
    """A Run's ``parameters``: the target, the options, the guidance's sources and the look's."""
    used_look = bool(result.parameters.get("attribute_channels"))
    return dict(target, **options, sources=guidance.sources,
                attributes=list(guidance.appearance_sources) if used_look else [])


def look_layers(run: Run) -> Optional[dict]:
    """The layers whose look was in ``run``'s cost, which the written result fits to the source's
    (mesh_write.fitted_look): {"uv": UV map name, "color": colour attribute name, "normal": bool},
    or None when the look was not in it."""
    if not run.result.parameters.get("attribute_channels"):
        return None
    used, mesh = run.guidance.appearance().used, run.obj.data
    color = appearance_color(mesh, run.obj.topstoc) if "color" in used else None
    uv = mesh.uv_layers.active if "uv" in used else None
    return {"uv": None if uv is None else uv.name, "color": None if color is None else color.name,
            "normal": "normal" in used}


def _object_materials(source, new) -> None:
    for index, slot in enumerate(source.material_slots):
        if slot.link == "OBJECT" and index < len(new.material_slots):
            new.material_slots[index].link = "OBJECT"
            new.material_slots[index].material = slot.material


def skin_weights(obj, arrays: mesh_read.MeshArrays, kept: np.ndarray, moved) -> tuple:
    """(group names, the output vertices' vertex-group weights): a vertex that did not move keeps
    its input vertex's; a moved one mixes its source triangle's (core/attributes.point_weights),
    rescaled to sum to 1 when the source's weights read (those of the kept vertices and of the
    moved vertices' triangles) all sum to 1."""
    corners = moved.source_corners(arrays.triangles, moved.moved).ravel()
    names, source = mesh_attributes.read_vertex_weights(obj, np.concatenate([kept, corners]))
    return names, point_weights(source, kept, moved, arrays.triangles, normalise=source.normalised())


def write_output(run: Run, mode: str = "NEW_OBJECT", name: str = None, place: bool = True,
                 into: bpy.types.Object = None) -> bpy.types.Object:
    """Writes a Run as a new object (default), into the object itself (IN_PLACE) or into an
    earlier result ``into`` (Regenerate); returns the object written.

    Shape keys, vertex groups, modifiers, parent, collections and custom properties follow the
    source (see carry.py). A new object goes beside the original (``place``; a rigged original
    is hidden instead); LOD chains and multiview lay their objects out themselves. Regenerating
    keeps the result's own transform, modifiers and materials and replaces only its mesh.
    """
    obj = run.obj
    kept = np.asarray(run.result.kept)
    arrays = run.prepared.arrays
    moved = run.moved if run.moved is not None else \
        moved_vertices_of(run.prepared.mesh, run.result)  # quality mode: interpolated
    group_names, weights = skin_weights(obj, arrays, kept, moved)
    shape_keys = carry.read_shape_keys(obj.data)
    if mode == "IN_PLACE" or into is not None:
        target = obj if into is None else into
        old = target.data
        mesh = mesh_write.build_result_mesh(obj.data, arrays, run.result, old.name + "_TopStoc", moved,
                                         guidance_layers(obj), keep_guidance=into is None, look=look_layers(run))
        if into is not None:  # the result's own material choices win over the source's
            mesh.materials.clear()
            for material in old.materials:
                mesh.materials.append(material)
            carry.copy_custom_properties(old, mesh)
        old_name = old.name
        target.data = mesh
        if old.users == 0:
            bpy.data.meshes.remove(old)
        mesh.name = old_name
    else:
        name = name or f"{obj.name}_TopStoc"
        mesh = mesh_write.build_result_mesh(obj.data, arrays, run.result, name, moved, guidance_layers(obj),
                                         keep_guidance=False, look=look_layers(run))
        carry.copy_custom_properties(obj.data, mesh)
        target = bpy.data.objects.new(name, mesh)
        carry.link_like(obj, target, bpy.context.scene)
        _object_materials(obj, target)
        carry.copy_modifiers(obj, target)
        carry.copy_custom_properties(obj, target)
        if place:
            carry.place_beside(obj, target)
    mesh_attributes.write_vertex_weights(target, group_names, weights)
    carry.write_shape_keys(target, shape_keys, arrays.vertices, run.result.vertices, kept, moved, arrays.triangles)
    target["topstoc_source"] = obj.name
    target["topstoc_parameters"] = json.dumps(run.parameters)
    # A missed target (control points painted, borders, symmetry, what the topology needs): the panel says so.
    target["topstoc_over_budget"] = int(run.result.stats.over_budget)
    target["topstoc_over_budget_reason"] = str(run.result.stats.over_budget_reason)
    missed = run.result.stats.target_missed
    target["topstoc_target_missed"] = "" if missed is None else missed.text()
    if target is not obj and run.settings is not None:  # what Regenerate needs (regenerate.py)
        target.topstoc.source = obj
        target.topstoc.settings = json.dumps(run.settings)
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
    stats = run.result.stats
    entry.parameters = json.dumps(dict(run.parameters, refine_vertices=int(stats.refine_vertices),
                                       refine_triangles=int(stats.refine_triangles),
                                       refine_keeps_positions=bool(stats.refine_keeps_positions),
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
    # a refined result used the look at its weight (sets saved before attributes existed: none)
    attributes = look_kwargs(dict(parameters, attribute_weight=parameters.get("attribute_weight", 0.0)),
                                  guidance.appearance) if refine_vertices else {}
    result = prepared.mesh.decimate_with_samples(samples, placement=parameters.get("placement", "subsample"),
                                                 refine_vertices=refine_vertices,
                                                 refine_triangles=int(parameters.get("refine_triangles", 0)),
                                                 refine_keeps_positions=bool(parameters.get("refine_keeps_positions")),
                                                 large_fit=parameters.get("mode") == "best",
                                                 guidance=guidance.guidance if refine_vertices else None,
                                                 **guidance.layout_kwargs(), **attributes)
    return Run(obj, prepared, guidance, result, parameters, time.perf_counter() - start)


def summary(run: Run, seconds: float = None) -> str:
    """One status-bar line: counts and time, and a missed target (how far off and why)."""
    report = run.prepared.mesh.report()
    seconds = run.seconds if seconds is None else seconds
    text = (f"{run.obj.name}: {report.input_vertices:,} -> {run.result.num_vertices:,} vertices, "
            f"{run.result.num_triangles:,} triangles in {seconds:.3f} s")
    bound = getattr(run.result, "error_bound", None)
    if bound is not None:
        text += f", deviation {bound.achieved_error:.4g} <= {bound.max_error:.4g}"
    if run.result.stats.repairs:
        text += (f" ({run.result.stats.repairs} topology repairs: vertices kept so that no hole closed and "
                 f"no handle or piece was lost)")
    missed = run.result.stats.target_missed
    if missed is not None:
        text += "; " + missed.text()
    return text


def decimate_many(context, obj, panel, variants) -> list:
    """Several decimations of one object in parallel (the engine releases the GIL).

    variants: (target kwargs, seed) pairs. Returns one Run per variant, in order.
    """
    start = time.perf_counter()
    prepared = prepare(obj)
    guidance = gather(obj, prepared.arrays, context.scene)
    prepared.mesh.feature_layout(guidance.regions, guidance.borders)  # built once, shared by the threads
    options = decimate_options(panel)
    try:
        jobs = [engine_job(prepared.mesh, target, dict(options, seed=seed), guidance) for target, seed in variants]
        with ThreadPoolExecutor(max_workers=max(1, min(len(variants), os.cpu_count() or 1))) as pool:
            results = list(pool.map(lambda job: run_engine(prepared.mesh, job), jobs))
    except ValueError as error:
        raise DecimationError(f"'{obj.name}': {error}") from None
    seconds = time.perf_counter() - start
    settings = settings_of(panel)

    def settings_for(target, seed):
        if "ratio" not in target:
            return None
        return dict(settings, target_mode="RATIO", ratio=target["ratio"], seed=seed)

    return [make_run(obj, prepared, guidance, result, target, dict(options, seed=seed), seconds,
                     settings_for(target, seed)) for (target, seed), result in zip(variants, results)]
