"""fresh_memory.empty: np.empty, or (under jemalloc, on Linux) an array over a mapping whose
pages the kernel maps at once."""

import ctypes
import mmap
import resource

import numpy as np
import pytest

from topstoc.core import fresh_memory


def test_without_jemalloc_arrays_come_from_numpy():
    # plain Python allocates with glibc: nothing to gain from a mapping of its own
    if hasattr(ctypes.CDLL(None), "mallctl"):
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
    b = np.empty(count, np.float64)  # numpy's array faults as it is touched (2 MB pages or 4 KB)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    b[:] = 1.5
    assert resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before >= 32
    small = fresh_memory.empty(100, np.int32)  # below POPULATE_MIN_BYTES: numpy's
    assert small.base is None
