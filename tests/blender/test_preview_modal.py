"""The Live Preview modal driven by simulated events in a windowed Blender under Xvfb."""

import os
import shutil
import subprocess

import pytest

from conftest import BUILD

XVFB = shutil.which("xvfb-run")
BLENDER = shutil.which("blender")


@pytest.mark.skipif(XVFB is None or BLENDER is None, reason="needs xvfb-run and a blender executable")
def test_preview_modal_drag_apply_cancel(ts):
    script = os.path.join(os.path.dirname(__file__), "preview_script.py")
    env = dict(os.environ, TOPSTOC_BUILD_PYTHON=str(BUILD / "python"))
    done = subprocess.run([XVFB, "-a", BLENDER, "--factory-startup", "--enable-event-simulate", "--python", script],
                          capture_output=True, text=True, timeout=300, env=env)
    lines = [line for line in done.stdout.splitlines() if line.startswith("preview check")]
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert len(lines) == 10 and all(line.endswith(": ok") for line in lines), lines
