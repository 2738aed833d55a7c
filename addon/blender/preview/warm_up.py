"""Live preview warm-ups: while the user drags (drafts on screen), an idle worker builds what the
rested Quality result resumes from, so that the rest only runs the part that depends on its ratio.

A quality decimation of a mesh collapsed whole goes the same way toward every target until its
collapses start to depend on the target; the engine keeps that state, and the input's search
structure, with the prepared mesh (core.api.decimate.warm_up, Mesh.kept_for_reuse). So does one
of a larger mesh from its first pass, where that pass is the same for lower targets. A warm-up
toward a ratio serves every rest at that ratio or below, with the same result to the bit as a
decimation that starts from nothing. A warm-up goes toward a little above the highest ratio
asked in the session (HEADROOM: the drag wanders up and down, and a state serves only ratios
below it), again when the drag goes above the states made (CLOSE). Not toward each ratio
of the drag: the mesh keeps two states (the highest, and the latest made), so states made along
the drag would push out the one a rest at the drag's start resumes from; a rest at a tenth of
the highest ratio still skips about nine tenths of a cold run's collapses. A rest waits for a warm-up that serves it instead of making the same collapses
beside it, and cancels one that cannot; closing the session cancels it.
"""

from __future__ import annotations

import threading
from typing import Callable, Optional

from ...core.api.decimate import CancelFlag
from ...core.api.loops import Cancelled

HEADROOM = 1.15  # a warm-up for ratio r goes toward HEADROOM r (capped at 1)
CLOSE = 1.3  # a state made toward w serves ratio r closely when r <= w <= CLOSE r


class WarmUps:
    """The warm-ups of one preview session (thread-safe). ``warm(ratio, cancel)`` runs one in the
    engine and returns whether a state is kept for such rests (False: none is toward that ratio,
    and none is tried again near it; the engine says so at once). A mesh too large to collapse
    whole keeps one only where its first pass is the same for lower ratios, which holds above
    some ratio and not below it, so a drag higher up may warm up after all."""

    def __init__(self, warm: Callable[[float, CancelFlag], bool]):
        self._warm = warm
        self._lock = threading.Lock()
        self._made: list = []        # ratios toward which a state was made (warm-ups and rests)
        self._futile: list = []      # ratios toward which a warm-up kept nothing
        self._running = None         # (ratio, CancelFlag, threading.Event set when it ends)
        self.applies = True          # False once one failed or the session closed
        self.finished = 0            # warm-ups run to their end

    def next(self, highest: float) -> Optional[float]:
        """The ratio to warm up toward now, for a drag whose highest ratio so far is ``highest``;
        None when none is wanted (a state made, or a warm-up that kept nothing, lies at most CLOSE
        times above it, or one runs)."""
        with self._lock:
            if not self.applies or self._running is not None:
                return None
            if any(highest <= made <= CLOSE * highest for made in self._made + self._futile):
                return None
            return min(1.0, HEADROOM * highest)

    def run(self, ratio: float) -> None:
        """One warm-up toward ``ratio`` (a worker; returns when it ends or is cancelled)."""
        with self._lock:
            if self._running is not None:
                return
            running = self._running = (ratio, CancelFlag(), threading.Event())
        kept, failed = None, False
        try:
            kept = self._warm(ratio, running[1])
        except Cancelled:
            pass
        except Exception:  # noqa: BLE001 - the rest's own decimation raises it where it is shown
            failed = True
        finally:
            with self._lock:
                self._running = None
                self.applies = self.applies and not failed
                if kept is not None:
                    self.finished += 1
                    (self._made if kept else self._futile).append(ratio)
            running[2].set()

    def settle(self, ratio: float, cancel: Optional[CancelFlag] = None) -> None:
        """Before a chosen-settings computation at ``ratio``: waits for a running warm-up toward
        it or above (the computation resumes from its state), cancels one toward a lower ratio.
        ``cancel`` (the computation's) set while it waits raises Cancelled."""
        with self._lock:
            running = self._running
        if running is None:
            return
        if running[0] < ratio:
            running[1].set()
            return
        while not running[2].wait(0.005):
            if cancel is not None and cancel.is_set:
                raise Cancelled("cancelled while a warm-up ran")

    def made(self, ratio: float) -> None:
        """A chosen-settings computation at ``ratio`` kept its own state."""
        with self._lock:
            self._made.append(ratio)

    def cancel(self) -> None:
        """Stops a running warm-up (the session closes)."""
        with self._lock:
            running = self._running
            self.applies = False
        if running is not None:
            running[1].set()

    @property
    def running(self) -> Optional[float]:
        """The ratio of the warm-up running now, or None."""
        with self._lock:
            return None if self._running is None else self._running[0]
