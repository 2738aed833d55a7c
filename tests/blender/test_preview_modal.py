"""The Live Preview modal driven by simulated events in a windowed Blender under Xvfb."""

import os

from conftest import BUILD
from launch import clean_environment, windowed


def test_preview_modal_drag_apply_cancel(ts):
    script = os.path.join(os.path.dirname(__file__), "preview_script.py")
    done = windowed(script, "--enable-event-simulate", env=clean_environment(TOPSTOC_BUILD_PYTHON=BUILD / "python"))
    lines = [line for line in done.stdout.splitlines() if line.startswith("preview check")]
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert len(lines) == 28 and all(line.endswith(": ok") for line in lines), lines
