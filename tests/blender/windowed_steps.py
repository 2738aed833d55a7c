"""What the windowed scripts (run in Blender under Xvfb with --enable-event-simulate) share:
one printed line per check, the 3D view's window, area and region, and a generator of steps
driven by Blender's timer (each step yields the seconds until the next; the process exits 0
only when every check held)."""

import os
import sys
import traceback

import bpy


class Checks:
    def __init__(self, prefix: str):
        self.prefix, self.failures = prefix, []

    def check(self, name, ok, detail=""):
        print(f"{self.prefix} check {name}: {'ok' if ok else 'FAILED'}"
              + ("" if ok or not detail else f" ({detail})"), flush=True)
        if not ok:
            self.failures.append(name)

    def finish(self):
        sys.stdout.flush()
        os._exit(1 if self.failures else 0)

    def drive(self, steps):
        """Runs the generator ``steps`` on Blender's timer, then exits."""
        def run():
            try:
                return next(steps)
            except StopIteration:
                self.finish()
            except Exception:
                traceback.print_exc()
                self.failures.append("exception")
                self.finish()

        bpy.app.timers.register(run, first_interval=1.0)


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, area, region
