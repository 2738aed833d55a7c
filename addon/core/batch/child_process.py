"""Child processes that die with the process that started them.

A batch task runs Blender as a child of a Dask worker. When the worker is killed (SIGKILL, the
out-of-memory killer), Dask reruns the task elsewhere, but the Blender child would go on as an
orphan, burning CPU for a result nobody reads. On Linux the kernel kills the child when its
parent dies (``prctl(PR_SET_PDEATHSIG, SIGKILL)``, set between fork and exec; it survives the
exec of a non-setuid program). Elsewhere the child is started as before.

The death signal fires when the *thread* that forked the child ends; ``run`` waits for the
child in that same thread, so the thread outlives the child unless the whole process dies.
"""

from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys

PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def _prctl():
    """libc's prctl, looked up before the fork (nothing is loaded in the forked child)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    prctl.argtypes = (ctypes.c_int, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong)
    prctl.restype = ctypes.c_int
    return prctl


def die_with_parent():
    """A ``preexec_fn`` that makes the child die with this process (None where unsupported)."""
    prctl = _prctl()
    if prctl is None:
        return None
    parent = os.getpid()

    def set_death_signal():
        if prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
        if os.getppid() != parent:  # the parent died between fork and prctl: nobody waits for us
            os.kill(os.getpid(), signal.SIGKILL)

    return set_death_signal


def run(command, **options) -> subprocess.CompletedProcess:
    """``subprocess.run`` with no standard input, killed when this process dies."""
    options.setdefault("stdin", subprocess.DEVNULL)
    return subprocess.run(command, preexec_fn=die_with_parent(), **options)
