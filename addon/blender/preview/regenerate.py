"""Non-destructive results: a result remembers its source object and the settings it ran with
(``obj.topstoc.source`` / ``obj.topstoc.settings``, saved in the .blend), and Regenerate runs
them again on the source's current mesh. Only the result's mesh is replaced: its transform,
modifiers, object and mesh material choices stay as the artist left them. The seed is part of
the settings, so a source that did not change gives the same mesh again.

Auto Regenerate: a depsgraph handler notes geometry updates of sources whose results asked for
it; a timer regenerates them once the source has been quiet for DEBOUNCE seconds and is not in
Edit Mode (the mesh data is only current in Object Mode).
"""

from __future__ import annotations

import json
import time
from types import SimpleNamespace

import bpy
from bpy.app.handlers import persistent

from ..decimation import pipeline

DEBOUNCE = 0.75  #: seconds of quiet after the last source edit

_pending: dict = {}  # result object name -> time of the latest source change


def source_of(result_obj):
    """The source object of a result (None: not a TopStoc result, or the source is gone)."""
    if result_obj is None or result_obj.type != "MESH":
        return None
    source = result_obj.topstoc.source
    return source if source is not None and source.name in bpy.data.objects else None


def why_not(result_obj):
    """Reason Regenerate cannot run on ``result_obj`` (None: it can)."""
    if result_obj is None:
        return "Select a TopStoc result first"
    if not result_obj.topstoc.settings:
        return f"'{result_obj.name}' is not a TopStoc result (made with New Object)"
    source = source_of(result_obj)
    if source is None:
        return f"The source of '{result_obj.name}' was deleted"
    if source.mode == "EDIT":
        return f"Leave Edit Mode on '{source.name}' first"
    return None


def regenerate(context, result_obj) -> pipeline.Run:
    """Re-runs the stored settings on the source and writes the mesh into ``result_obj``."""
    reason = why_not(result_obj)
    if reason is not None:
        raise pipeline.DecimationError(reason)
    # results made before UVs and colours entered the cost ran without them: keep it so
    params = SimpleNamespace(**{"attribute_weight": 0.0, **json.loads(result_obj.topstoc.settings)})
    run = pipeline.decimate(context, result_obj.topstoc.source, params)
    pipeline.write_output(run, into=result_obj)
    return run


def results_of(source) -> list:
    return [obj for obj in bpy.data.objects if obj.type == "MESH" and obj.topstoc.source == source]


@persistent
def _on_depsgraph_update(scene, depsgraph=None):
    depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
    now = time.monotonic()
    for update in depsgraph.updates:
        if not (update.is_updated_geometry and isinstance(update.id, bpy.types.Object)):
            continue
        source = update.id.original
        for result in results_of(source):
            if result.topstoc.auto_regenerate and result is not source:
                _pending[result.name] = now
    if _pending and not bpy.app.timers.is_registered(run_pending):
        bpy.app.timers.register(run_pending, first_interval=DEBOUNCE)


def run_pending(now: float = None):
    """Regenerates the results whose sources have been quiet long enough; the timer's function
    (returns the delay until the next check, or None when nothing waits)."""
    now = time.monotonic() if now is None else now
    for name, changed in list(_pending.items()):
        result = bpy.data.objects.get(name)
        if result is None or source_of(result) is None:
            _pending.pop(name, None)
            continue
        if now - changed < DEBOUNCE or result.topstoc.source.mode == "EDIT":
            continue  # still being edited
        _pending.pop(name, None)
        try:
            regenerate(bpy.context, result)
        except (pipeline.DecimationError, ValueError) as error:
            print(f"TopStoc: could not regenerate '{name}': {error}")
    return DEBOUNCE if _pending else None


def register():
    bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph_update)


def unregister():
    if _on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_depsgraph_update)
    if bpy.app.timers.is_registered(run_pending):
        bpy.app.timers.unregister(run_pending)
    _pending.clear()
