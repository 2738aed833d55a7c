"""Runs a script in a second process of the Blender under test, in a clean environment.

- A real Blender (Debian's 3.4; 4.3 in the Debian 13 root): the running binary,
  ``bpy.app.binary_path -b --factory-startup --python-exit-code 1 --python SCRIPT -- ARGS``.
- PyPI's ``bpy`` (a module: ``binary_path`` is empty): this interpreter runs the script after
  ``import bpy``, with ``sys.argv`` as Blender would set it, so ``sys.argv[sys.argv.index("--")+1:]``
  gives the script its arguments. What needs a window (undo, simulated events) is skipped there:
  the module has none.

The child gets only PATH, HOME, locale and temp-folder variables: nothing this process picked up
(``OCIO`` set by bpy 5.x, which Blender 3.4's OpenColorIO cannot read; PYTHONPATH; BLENDER_*).
"""

import os
import shutil
import subprocess
import sys
import tempfile

import bpy
import pytest

BINARY = bpy.app.binary_path or None
IS_MODULE = BINARY is None
XVFB = shutil.which("xvfb-run")
_KEPT = ("PATH", "HOME", "LANG", "LC_ALL", "TMPDIR", "USER", "LOGNAME")

# Runs argv[1] (a file) or argv[2] (code, when argv[1] is empty) as `blender -b --python-exit-code 1`
# would, then leaves with os._exit: bpy 4.5's module deadlocks in interpreter shutdown after a script
# that used it (seen with batch.py: outputs written, then every thread waiting on a futex).
_MODULE_MAIN = """import os, runpy, sys, traceback
script, code = sys.argv[1], sys.argv[2]
sys.argv = ["blender", "-b", "--python", script or "-"] + sys.argv[3:]
import bpy
status = 0
try:
    if script:
        runpy.run_path(script, run_name="__main__")
    else:
        exec(compile(code, "<python-expr>", "exec"), {"__name__": "__main__"})
except SystemExit as done:
    if isinstance(done.code, str):
        print(done.code, file=sys.stderr)
    status = done.code if isinstance(done.code, int) else int(done.code is not None)
except BaseException:
    traceback.print_exc()
    status = 1
sys.stdout.flush()
sys.stderr.flush()
os._exit(status)
"""


def clean_environment(**extra) -> dict:
    """The child's environment: the kept variables of this one plus ``extra``."""
    env = {key: os.environ[key] for key in _KEPT if key in os.environ}
    env.update({key: str(value) for key, value in extra.items()})
    return env


def background(script=None, *args, expr=None, timeout=300, env=None) -> subprocess.CompletedProcess:
    """Runs ``script`` (a path) or ``expr`` (Python code) in a background Blender; ``args`` follow
    ``--``. Returns the finished process (text output captured)."""
    args = [str(a) for a in args]
    if IS_MODULE:
        command = [sys.executable, "-c", _MODULE_MAIN, str(script or ""), expr or "", "--", *args]
    else:
        source = ["--python", str(script)] if script else ["--python-expr", expr]
        command = [BINARY, "-b", "--factory-startup", "--python-exit-code", "1", *source, "--", *args]
    return _run_keeping_crash_report(command, env if env is not None else clean_environment(), timeout)


def windowed(script, *options, timeout=300, env=None) -> subprocess.CompletedProcess:
    """Runs ``script`` in a windowed Blender under Xvfb (skips where there is no window to open)."""
    if IS_MODULE:
        pytest.skip("PyPI's bpy is a module without a window; runs in the suite under a Blender binary (Debian's 3.4)")
    if XVFB is None:
        pytest.skip("needs xvfb-run")
    command = [XVFB, "-a", BINARY, "--factory-startup", *options, "--python", str(script)]
    return _run_keeping_crash_report(command, env if env is not None else clean_environment(), timeout)


def _run_keeping_crash_report(command, env, timeout) -> subprocess.CompletedProcess:
    """Runs ``command`` with a temp folder of its own; when Blender crashed, the report it wrote
    there (blender.crash.txt: the backtrace) is added to the captured stderr, so that a rare
    crash in a test run can be read afterwards."""
    with tempfile.TemporaryDirectory(prefix="topstoc-blender-") as temp:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                              env={**env, "TMPDIR": temp, "TEMP": temp})
        report = os.path.join(temp, "blender.crash.txt")
        if done.returncode != 0 and os.path.exists(report):
            with open(report, errors="replace") as crash:
                done.stderr += f"\n--- {report} ---\n" + crash.read()
    return done
