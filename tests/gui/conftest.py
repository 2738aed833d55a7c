"""Real-GUI tests: each test builds a scene with `blender -b`, then opens it in a windowed
Blender under `xvfb-run -a` that runs one script (several checks and screenshots per launch).
The tests themselves run in plain Python (no bpy): they read the script's report.json and the
screenshots' pixels (.npy) and check colours in the objects' screen regions.

    python -m pytest tests/gui        # needs xvfb-run, blender and a build (skips otherwise)
    TOPSTOC_BLENDER=/path/to/blender TOPSTOC_BUILD=build-trixie python -m pytest tests/gui

TOPSTOC_BLENDER picks the Blender binary (default: `blender` on PATH); TOPSTOC_BUILD the staged
build whose module that Blender's Python can load (build-trixie for Debian 13's Blender 4.3).
"""

import json
import os
import pathlib
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))
DATA = ROOT / "tests" / "data"
HERE = pathlib.Path(__file__).resolve().parent
XVFB = shutil.which("xvfb-run")
BLENDER = shutil.which(os.environ.get("TOPSTOC_BLENDER", "blender"))
_KEPT = ("PATH", "HOME", "LANG", "LC_ALL", "TMPDIR", "USER", "LOGNAME", "TOPSTOC_DOC_SHOTS")


def _environment():
    """A clean environment for Blender: nothing of this process's (OCIO, PYTHONPATH, BLENDER_*)."""
    env = {key: os.environ[key] for key in _KEPT if key in os.environ}
    env["TOPSTOC_BUILD_PYTHON"] = str(BUILD / "python")
    return env


@pytest.fixture(scope="session")
def gui():
    """Skips unless a windowed Blender can run here."""
    if XVFB is None or BLENDER is None:
        pytest.skip("needs xvfb-run and a blender executable")
    if not (BUILD / "python" / "topstoc" / "__init__.py").exists():
        pytest.skip(f"no staged package under {BUILD}; build first")
    return GuiRunner()


class GuiRunner:
    def scene(self, path: pathlib.Path, *args, timeout: int = 300) -> pathlib.Path:
        """Makes a saved scene with tests/gui/make_scene.py (background Blender)."""
        command = [BLENDER, "-b", "--factory-startup", "--python-exit-code", "1",
                   "--python", str(HERE / "make_scene.py"), "--", "--output", str(path), *map(str, args)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=_environment())
        assert done.returncode == 0 and path.exists(), done.stdout[-3000:] + done.stderr[-3000:]
        return path

    def run(self, script: str, scene: pathlib.Path, out: pathlib.Path, *args, timeout: int = 300,
            screen: str = "1280x1024") -> dict:
        """Opens ``scene`` in a windowed Blender running tests/gui/<script>; returns its report.
        ``screen``: the Xvfb screen (the window fills it)."""
        out.mkdir(parents=True, exist_ok=True)
        command = [XVFB, "-a", "-s", f"-screen 0 {screen}x24", BLENDER, "--factory-startup",
                   "--enable-event-simulate", str(scene),
                   "--python-exit-code", "1", "--python", str(HERE / script), "--", str(out), *map(str, args)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=_environment(),
                              cwd=str(HERE))
        report_path = out / "report.json"
        assert report_path.exists(), done.stdout[-4000:] + done.stderr[-4000:]
        report = json.loads(report_path.read_text())
        assert report["error"] is None, report["error"]
        assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
        report["log"] = done.stdout
        return report
