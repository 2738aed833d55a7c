"""Peak memory of one prepare + decimate on a generated mesh, measured in a fresh process.

Shared by tests/bench/bench_scale.py (2M to 100M triangles), tests/bench/bench_families.py (each
shape family at one size) and tests/python/test_memory_ceiling.py (2M). The child process
imports numpy and topstoc, makes one decimation of a 2,000-triangle mesh (what NumPy imports on
first use and the engine's threads), reads its resident size (the baseline: the interpreter,
the modules, the threads), generates the mesh (tests/shape_families.py: the bumpy torus unless
asked), resets the kernel's high-water mark (/proc/self/clear_refs, so that the
generator's temporaries are not counted), then prepares and decimates. The figure is
(high-water mark - baseline) / input triangles: the input arrays (float64 vertices, int32
triangles, 24 bytes a triangle) are included, as the caller holds them throughout. The same is
given for the preparation alone (its high-water mark) and for what the prepared mesh holds
(resident size once prepared), so that a change shows which of the two it moved.
"""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))

CHILD = r"""
import json, sys, time
sys.path[:0] = [{python!r}, {tests!r}]
import numpy as np
from topstoc.core import Mesh
import meshgen, shape_families

def status(name):
    with open("/proc/self/status") as handle:
        for line in handle:
            if line.startswith(name + ":"):
                return int(line.split()[1]) * 1024
    raise RuntimeError(name + " not in /proc/self/status")

# A small decimation first, so that what any decimation loads once (the modules NumPy imports on
# first use, the threads) is in the baseline, not counted per triangle.
warm = Mesh(*meshgen.bumpy_torus(2000))
warm.decimate(ratio=0.1, mode={mode!r}, seed=1)
del warm
base = status("VmRSS")
vertices, triangles = shape_families.FAMILIES[{family!r}]({triangles})
vertices = np.ascontiguousarray(vertices, dtype=np.float64)
triangles = np.ascontiguousarray(triangles, dtype=np.int32)
with open("/proc/self/clear_refs", "w") as handle:
    handle.write("5")  # the high-water mark starts again from the arrays in hand
start = time.perf_counter()
mesh = Mesh(vertices, triangles)
prepared = time.perf_counter()
status_at_prepared = status("VmRSS") - base
prepare_peak = status("VmHWM") - base
result = mesh.decimate(ratio={ratio}, mode={mode!r}, seed=1)
done = time.perf_counter()
print(json.dumps({{"triangles": len(triangles), "vertices": len(vertices), "prepare_s": prepared - start,
                  "decimate_s": done - prepared, "peak_bytes": status("VmHWM") - base,
                  "prepare_peak_bytes": prepare_peak, "prepared_bytes": status_at_prepared,
                  "output_vertices": len(result.vertices), "output_triangles": len(result.triangles),
                  "target_missed": result.stats.target_missed is not None,
                  "topology_kept": bool(result.stats.topology_kept)}}))
"""


def measure(triangles: int, mode: str, ratio: float = 0.01, family: str = "bumpy_torus",
            build: pathlib.Path = BUILD) -> dict:
    """One prepare + decimate of `family` (tests/shape_families.py; the bumpy torus by default) of
    about `triangles` triangles in a fresh process of `build`: times, peak bytes above the
    interpreter's baseline and per input triangle, output size."""
    code = CHILD.format(python=str(build / "python"), tests=str(ROOT / "tests"), triangles=int(triangles),
                        ratio=float(ratio), mode=mode, family=family)
    env = {**os.environ, "TOPSTOC_BUILD": str(build)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    if done.returncode != 0:
        raise RuntimeError(f"the {mode} run on {family} of {triangles} triangles failed:\n{done.stderr[-2000:]}")
    figures = json.loads(done.stdout.splitlines()[-1])
    triangles = figures["triangles"]
    figures["bytes_per_triangle"] = figures["peak_bytes"] / triangles  # the whole run
    figures["prepare_bytes_per_triangle"] = figures["prepare_peak_bytes"] / triangles  # the preparation's peak
    figures["prepared_bytes_per_triangle"] = figures["prepared_bytes"] / triangles  # held once prepared
    return figures


def available() -> bool:
    """The kernel lets a process reset its own high-water mark (Linux 4.0 and later)."""
    return os.access("/proc/self/clear_refs", os.W_OK)
