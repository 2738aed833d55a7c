"""Large arrays whose memory is mapped in one call where the allocator would not reuse it.

Reading a Blender mesh copies it into new arrays: tens of MB on the main thread for a large mesh
when the Live Preview starts. The kernel maps new memory a page at a time,
on first touch. Where the process allocates with jemalloc, freed memory goes back to the
kernel (blocks of 8 MB or more at once, smaller ones after a few seconds), so a start after a
pause faulted in every page again (and numpy's request for 2 MB pages on large arrays may make
the kernel compact memory first). An anonymous mapping with MAP_POPULATE maps all its pages in
one system call, several times faster. With glibc's allocator (PyPI's bpy, plain Python) freed
memory is reused without faults and a fresh mapping costs more, so there arrays come from
np.empty as before (the runs: docs/benchmarks.md).

jemalloc is recognised by a function only it defines, visible to dlsym: `mallctl` where it is a
shared library (Debian's Blender 3.4 links libjemalloc.so.2), `mallocx` where a program links it
statically. Blender's own Linux builds do that and export only the names their symbol map lists
(source/creator/symbols_unix.map: Py*, malloc*, free, ... and nothing else), so `mallctl` is
hidden there while `mallocx`, matching malloc*, is exported.
"""

from __future__ import annotations

import ctypes
import functools
import mmap

import numpy as np

# Below this the allocator's own free lists serve (and a mapping per array would cost more).
POPULATE_MIN_BYTES = 1 << 20

# Functions of jemalloc's own API, with and without the prefix some platforms' builds give it.
JEMALLOC_FUNCTIONS = ("mallctl", "mallocx", "je_mallctl", "je_mallocx")


@functools.lru_cache(maxsize=None)
def _populate_flag() -> int:
    """MAP_POPULATE where the process allocates with jemalloc and mmap has the flag, else 0."""
    flag = getattr(mmap, "MAP_POPULATE", 0)
    if not flag:
        return 0
    try:
        process = ctypes.CDLL(None)
    except (OSError, TypeError):  # no dlopen(NULL) (Windows)
        return 0
    return flag if any(hasattr(process, name) for name in JEMALLOC_FUNCTIONS) else 0


def empty(count: int, dtype) -> np.ndarray:
    """``np.empty(count, dtype)``; under jemalloc its pages are mapped at once (see above), and
    the mapping is released with the last array that uses it."""
    dtype = np.dtype(dtype)
    size = count * dtype.itemsize
    populate = _populate_flag()
    if size < POPULATE_MIN_BYTES or not populate:
        return np.empty(count, dtype)
    buffer = mmap.mmap(-1, size, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS | populate)
    return np.frombuffer(buffer, dtype=dtype, count=count)
