"""The launcher of second Blender processes (launch.py) keeps what a crash leaves behind."""

import pytest

from launch import IS_MODULE, background


def test_a_crashing_blender_leaves_its_report_in_the_result():
    """A rare crash in a subprocess test must be readable afterwards: the launcher adds the
    report Blender writes (blender.crash.txt, in the run's own temp folder) to stderr."""
    if IS_MODULE:
        pytest.skip("PyPI's bpy writes no crash report (a module, not Blender's main)")
    done = background(expr="import ctypes; ctypes.string_at(0)")  # reads address 0: a segfault
    assert done.returncode != 0
    assert "blender.crash.txt ---" in done.stderr and "backtrace" in done.stderr, done.stderr[-2000:]
