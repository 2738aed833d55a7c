"""The engine's own threads: no OpenMP runtime is loaded, and TOPSTOC_NUM_THREADS (or else
OMP_NUM_THREADS) caps the worker threads a large decimation starts (Linux: /proc lists them)."""

import os
import subprocess
import sys

import pytest

from conftest import BUILD

TESTS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Decimates a 180,000-vertex torus (past the engine's parallel cut-off), then prints how many
# threads the decimation added to the process and whether an OpenMP runtime is mapped.
SCRIPT = """
import os, sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]
import meshgen
from topstoc.core import Mesh
vertices, triangles = meshgen.torus(600, 300)
before = len(os.listdir("/proc/self/task"))
Mesh(vertices, triangles).decimate(ratio=0.1, seed=1, mode="fast")
added = len(os.listdir("/proc/self/task")) - before
maps = open("/proc/self/maps").read()
print(added, any(name in maps for name in ("libgomp", "libomp", "libiomp")))
"""

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="needs /proc (Linux)")


def run(**env) -> tuple:
    clean = {k: v for k, v in os.environ.items() if k not in ("TOPSTOC_NUM_THREADS", "OMP_NUM_THREADS")}
    out = subprocess.run([sys.executable, "-c", SCRIPT, str(BUILD / "python"), TESTS], env={**clean, **env},
                         capture_output=True, text=True, check=True).stdout.split()
    return int(out[0]), out[1] == "True"


@pytest.mark.parametrize("variable", ["TOPSTOC_NUM_THREADS", "OMP_NUM_THREADS"])
def test_a_limit_of_one_thread_starts_no_worker(variable):
    added, openmp = run(**{variable: "1"})
    assert added == 0
    assert not openmp


def test_without_a_limit_workers_stay_within_the_cores_and_no_openmp_runtime_loads():
    added, openmp = run()
    assert 0 <= added <= max(1, os.cpu_count()) - 1  # the calling thread works too
    assert not openmp
