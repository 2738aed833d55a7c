"""Undo restores in-place results (runs a windowed Blender under Xvfb: undo needs a window)."""

import os

from conftest import BUILD
from launch import clean_environment, windowed


def test_undo_and_redo_in_a_window(ts):
    script = os.path.join(os.path.dirname(__file__), "undo_script.py")
    done = windowed(script, env=clean_environment(TOPSTOC_BUILD_PYTHON=BUILD / "python"))
    lines = [line for line in done.stdout.splitlines() if line.startswith("undo check")]
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert len(lines) == 5 and all(line.endswith(": ok") for line in lines), lines
