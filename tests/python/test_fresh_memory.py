"""fresh_memory.empty: np.empty, or (under jemalloc, on Linux) an array over a mapping whose
pages the kernel maps at once."""

import ctypes
import glob
import mmap
import os
import resource
import subprocess
import sys

import numpy as np
import pytest

from topstoc.core.support import fresh_memory


def test_without_jemalloc_arrays_come_from_numpy():
    # plain Python allocates with glibc: nothing to gain from a mapping of its own
    if any(hasattr(ctypes.CDLL(None), name) for name in fresh_memory.JEMALLOC_FUNCTIONS):
        pytest.skip("this Python allocates with jemalloc")
    fresh_memory._populate_flag.cache_clear()
    assert fresh_memory._populate_flag() == 0
    a = fresh_memory.empty(1 << 20, np.float64)
    assert a.shape == (1 << 20,) and a.dtype == np.float64 and a.flags.writeable


@pytest.mark.skipif(not hasattr(mmap, "MAP_POPULATE"), reason="MAP_POPULATE is Linux's")
def test_populated_arrays_are_mapped_before_they_are_touched(monkeypatch):
    monkeypatch.setattr(fresh_memory, "_populate_flag", lambda: mmap.MAP_POPULATE)
    count = 8 << 20  # 64 MB of float64
    a = fresh_memory.empty(count, np.float64)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    a[:] = 1.5  # every page written: none faults, all were mapped by empty()
    assert resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before < 8
    assert isinstance(a.base, memoryview) and a.flags.writeable and a.shape == (count,)
    assert a.sum() == 1.5 * count
    # a mapping without MAP_POPULATE faults as it is touched (2 MB pages or 4 KB); np.empty did
    # too, unless glibc served it from heap pages an earlier test had freed (0 faults, once)
    b = np.frombuffer(memoryview(mmap.mmap(-1, count * 8)), np.float64)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    b[:] = 1.5
    assert resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before >= 32
    small = fresh_memory.empty(100, np.int32)  # below POPULATE_MIN_BYTES: numpy's
    assert small.base is None


JEMALLOC_LIBRARIES = glob.glob("/usr/lib/*/libjemalloc.so.2") + glob.glob("/usr/lib/libjemalloc.so.2")


@pytest.mark.skipif(not hasattr(mmap, "MAP_POPULATE") or not JEMALLOC_LIBRARIES, reason="needs Linux and libjemalloc")
def test_a_process_allocating_with_jemalloc_maps_arrays_at_once():
    # Debian's Blender 3.4 links libjemalloc.so.2; a Python started with it preloaded allocates
    # the same way (numpy's arrays too) and sees jemalloc's functions through dlsym.
    script = (
        "import mmap, numpy as np; from topstoc.core.support import fresh_memory; "
        "assert fresh_memory._populate_flag() == mmap.MAP_POPULATE; "
        "a = fresh_memory.empty(1 << 20, np.float64); assert isinstance(a.base, memoryview); print('ok')"
    )
    env = dict(os.environ, LD_PRELOAD=JEMALLOC_LIBRARIES[0])
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    run = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr


class _Process:
    """What dlsym finds in a process: the names given."""

    def __init__(self, *names):
        for name in names:
            setattr(self, name, object())


@pytest.mark.skipif(not hasattr(mmap, "MAP_POPULATE"), reason="MAP_POPULATE is Linux's")
@pytest.mark.parametrize(
    "exported, populates",
    [
        # Blender's Linux builds link jemalloc statically and export malloc* only: mallocx, not mallctl
        (("malloc", "free", "mallocx", "malloc_usable_size", "malloc_stats_print"), True),
        (("malloc", "free", "mallctl", "mallocx"), True),  # a shared libjemalloc
        (("malloc", "free", "malloc_usable_size", "mallinfo"), False),  # glibc
    ],
)
def test_jemalloc_is_recognised_by_its_own_functions(monkeypatch, exported, populates):
    monkeypatch.setattr(fresh_memory.ctypes, "CDLL", lambda name: _Process(*exported))
    fresh_memory._populate_flag.cache_clear()
    try:
        assert fresh_memory._populate_flag() == (mmap.MAP_POPULATE if populates else 0)
    finally:
        fresh_memory._populate_flag.cache_clear()
