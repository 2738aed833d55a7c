"""Array digests for the add-on's caches (topstoc.core.support.digest, the engine's content digest)."""

import os
import subprocess
import sys

import numpy as np

from conftest import BUILD
from topstoc.core.support.digest import array_digest
from topstoc.core.support.native import engine


def test_any_changed_byte_dtype_or_shape_changes_the_digest():
    rng = np.random.default_rng(5)
    a = rng.normal(size=(700_000, 3))  # 16.8 MB: several 1 MiB blocks, digested in parallel
    base = array_digest(a)
    assert array_digest(a.copy()) == base
    for index in (0, 1, 12345, a.size - 1):
        b = a.copy()
        b.reshape(-1)[index] = np.nextafter(b.reshape(-1)[index], np.inf)  # one bit of one value
        assert array_digest(b) != base
    swapped = a.copy()
    swapped[[10, 11]] = swapped[[11, 10]]
    assert array_digest(swapped) != base
    assert array_digest(a.astype(np.float32)) != base
    assert array_digest(a.reshape(-1, 1)) != base
    assert array_digest(a, None) != array_digest(a) != array_digest(None, a)
    # every length near a stripe and a block boundary gives its own digest
    seen = {engine.content_digest(np.zeros(k, dtype=np.uint8)) for k in range(0, 70)}
    seen |= {engine.content_digest(np.zeros((1 << 20) + k, dtype=np.uint8)) for k in (-1, 0, 1)}
    assert len(seen) == 73


def test_the_digest_does_not_depend_on_the_number_of_threads():
    code = ("import numpy as np; from topstoc.core.support.digest import array_digest; "
            "print(array_digest(np.arange(3_000_000, dtype=np.int64) * 7919 % 1000003))")
    outputs = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                              env={**os.environ, "TOPSTOC_NUM_THREADS": threads, "PYTHONPATH": str(BUILD / "python")}).stdout for threads in ("1", "2")}
    assert len(outputs) == 1
