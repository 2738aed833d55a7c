"""Bake Normals run by an operator after its decimations: the ray cast's progress in the window's
progress cursor; a cancelled bake removes the run's results, so the scene is as before the run."""

from __future__ import annotations

from ..decimation import bake
from ..decimation.bake_raycast import Cancelled


def cursor_progress(context):
    """The bake's progress callback: the window's progress cursor (0-100). Returning False
    cancels the bake (the tests' hook)."""
    wm = context.window_manager

    def told(fraction: float) -> bool:
        wm.progress_update(int(100 * fraction))
        return True
    return told


def bake_or_discard(context, settings, pairs, results):
    """(status lines, one-line failures) of baking every (source, result) pair; None when the bake
    was cancelled, after removing ``results`` and what their bakes made."""
    wm = context.window_manager
    wm.progress_begin(0, 100)
    try:
        return bake.bake_results(context, settings, pairs, progress=cursor_progress(context))
    except Cancelled:
        bake.remove_results(results)
        return None
    finally:
        wm.progress_end()
