"""Bake Normals run by an operator after its decimations, one step at a time: at once from
execute (progress in the window's cursor), or modal (BakeModal: a step per timer event, progress
in the cursor and the area's header, Esc cancels). A cancelled bake removes the run's results, so
the scene is as before the run."""

from __future__ import annotations

import bpy

from ..decimation import bake
from ..decimation.bake_raycast import Cancelled, drive

STEP_SECONDS = 0.01  #: the modal bake's timer: a step (a chunk of rays, a Cycles bake) per event


class SteppedBake:
    """Bakes every (source, result) pair with an operator's BakeParameters one step() at a time."""

    def __init__(self, context, settings, pairs, results):
        self.results = list(results)
        self.steps = bake.bake_results_steps(context, settings, pairs)
        self.fraction = 0.0
        self.done = None  #: (status lines, one-line failures) once finished

    def step(self) -> bool:
        """Runs one step; True when the bake is finished (``done`` holds its lines and failures)."""
        try:
            self.fraction = next(self.steps)
        except StopIteration as finished:
            self.fraction, self.done = 1.0, finished.value
            return True
        return False

    def cancel(self) -> None:
        """Stops the bake (the result being baked is put back) and removes the run's results."""
        self.steps.close()
        bake.remove_results(self.results)


def cursor_progress(context):
    """The bake's progress callback: the window's progress cursor (0-100). Returning False
    cancels the bake (the tests' hook)."""
    wm = context.window_manager

    def told(fraction: float) -> bool:
        wm.progress_update(int(100 * fraction))
        return True
    return told


def bake_or_discard(context, settings, pairs, results):
    """(status lines, one-line failures) of baking every (source, result) pair at once; None when
    the bake was cancelled, after removing ``results`` and what their bakes made."""
    wm = context.window_manager
    wm.progress_begin(0, 100)
    run = SteppedBake(context, settings, pairs, results)
    try:
        return drive(run.steps, cursor_progress(context))
    except Cancelled:
        bake.remove_results(results)
        return None
    finally:
        wm.progress_end()


def can_run_modal(context) -> bool:
    """Whether a modal bake gets events: a window, and not Blender in background mode."""
    return context.window is not None and not bpy.app.background


class BakeModal:
    """For an operator whose bake runs modal: it calls start_bake after its decimations and
    returns what that returns; Blender then calls modal on every event; when the bake ends the
    operator's bake_finished(context, (lines, failures)) gives the operator's result, and on Esc
    the run is cancelled (its results removed: the scene as before)."""

    def start_bake(self, context, pairs, results):
        self._bake = SteppedBake(context, self, pairs, results)
        context.window_manager.progress_begin(0, 100)
        self._listen(context)
        return {"RUNNING_MODAL"}

    def bake_cancelled(self, context) -> None:
        """Removes what the operator made besides the results (after Esc); nothing by default."""

    def _listen(self, context) -> None:
        """Blender's timer and modal handler for this operator."""
        wm = context.window_manager
        self._timer = wm.event_timer_add(STEP_SECONDS, window=context.window)
        if not getattr(self, "_in_modal", False):  # already modal (Guided Decimate's worker run)
            wm.modal_handler_add(self)

    def _stop_listening(self, context) -> None:
        context.window_manager.event_timer_remove(self._timer)

    def _end_bake(self, context) -> None:
        self._stop_listening(context)
        context.window_manager.progress_end()
        if context.area is not None:
            context.area.header_text_set(None)

    def modal(self, context, event):
        if event.type == "ESC":
            self._end_bake(context)
            self._bake.cancel()
            self.bake_cancelled(context)
            self.report({"WARNING"}, "TopStoc: Bake Normals cancelled; nothing was changed")
            return {"CANCELLED"}
        if event.type != "TIMER":  # (Blender's Event does not say which timer fired)
            return {"RUNNING_MODAL"}  # the scene is set up for the bake: other input waits
        try:
            finished = self._bake.step()
        except BaseException:
            self._end_bake(context)
            self._bake.cancel()
            self.bake_cancelled(context)
            raise
        context.window_manager.progress_update(int(100 * self._bake.fraction))
        if context.area is not None:
            context.area.header_text_set(f"Baking normals: {100 * self._bake.fraction:.0f} % (Esc cancels)")
        if not finished:
            return {"RUNNING_MODAL"}
        self._end_bake(context)
        return self.bake_finished(context, self._bake.done)
