"""Guided Decimate's modal run (worker thread, progress, Esc) driven in a windowed Blender under Xvfb."""

import os

from conftest import BUILD
from launch import clean_environment, windowed


def test_guided_decimate_modal_esc_and_completion(ts):
    script = os.path.join(os.path.dirname(__file__), "decimate_modal_script.py")
    done = windowed(script, "--enable-event-simulate", env=clean_environment(TOPSTOC_BUILD_PYTHON=BUILD / "python"))
    lines = [line for line in done.stdout.splitlines() if line.startswith("decimate check")]
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert len(lines) == 17 and all(line.endswith(": ok") for line in lines), lines
