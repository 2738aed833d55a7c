"""Peak memory of one decimation of a generated object, run by launch.background in a fresh Blender.

    ... -- KIND TRIANGLES MODE RATIO     (KIND: addon or engine; MODE: QUALITY or FAST)

The bumpy torus (tests/meshgen.py) becomes a mesh object; the generator's arrays are dropped and
the heap trimmed, and the baseline is the resident size then, Blender's own mesh included. Then
the kernel's high-water mark is reset (/proc/self/clear_refs) and one of:
- addon: Guided Decimate's worker path: read on the main thread, prepare and decimate on the
  worker (decimation/background.py), the result written as a new object;
- engine: the engine alone on the arrays the add-on reads (float64 positions, int32 triangles,
  the input arrays every figure includes): Mesh(...).decimate.
Prints one JSON line: triangles, peak bytes above the baseline, per triangle, seconds, output size.
"""

import ctypes
import gc
import json
import os
import pathlib
import sys
import time

import bpy  # first: PyPI's bpy module makes addon_utils importable
import addon_utils  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
sys.path[:0] = [os.environ["TOPSTOC_BUILD_PYTHON"], str(HERE.parent), str(HERE)]
import meshgen  # noqa: E402
from helpers import Params  # noqa: E402


def status(name: str) -> int:
    with open("/proc/self/status") as handle:
        for line in handle:
            if line.startswith(name + ":"):
                return int(line.split()[1]) * 1024
    raise RuntimeError(name + " not in /proc/self/status")


def bumpy_object(triangles: int, ts):
    vertices, faces = meshgen.bumpy_torus(triangles)
    mesh = bpy.data.meshes.new("Big")
    ts.blender.io.mesh_write.fill_geometry(mesh, vertices, faces)
    obj = bpy.data.objects.new("Big", mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def addon_run(ts, obj, mode: str, ratio: float) -> int:
    pipeline = ts.blender.decimation.pipeline
    job = ts.blender.decimation.background.BackgroundDecimation(
        [pipeline.read_input(bpy.context, obj, Params(ratio=ratio, quality=mode, seed=1))])
    assert job.wait(3600), "the worker did not end"
    run, failure = job.outcomes[0]
    assert failure is None, failure
    return len(pipeline.write_output(run).data.vertices)


def engine_run(ts, obj, mode: str, ratio: float) -> int:
    arrays = ts.blender.io.mesh_read.read_mesh(obj.data)
    result = ts.core.Mesh(arrays.vertices, arrays.triangles).decimate(ratio=ratio, mode=mode.lower(), seed=1)
    return len(result.vertices)


def main(kind: str, triangles: int, mode: str, ratio: float) -> None:
    addon_utils.enable("topstoc", default_set=True)
    import topstoc as ts
    import topstoc.blender.decimation.background  # noqa: F401

    obj = bumpy_object(triangles, ts)
    gc.collect()
    ctypes.CDLL("libc.so.6").malloc_trim(0)  # the generator's freed arrays are not the baseline
    base = status("VmRSS")
    with open("/proc/self/clear_refs", "w") as handle:
        handle.write("5")
    start = time.perf_counter()
    out = (addon_run if kind == "addon" else engine_run)(ts, obj, mode, ratio)
    seconds = time.perf_counter() - start
    peak, m = status("VmHWM") - base, len(obj.data.polygons)
    print(json.dumps({"kind": kind, "mode": mode, "triangles": m, "peak_bytes": peak,
                      "bytes_per_triangle": peak / m, "seconds": seconds, "output_vertices": out}), flush=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:]
    main(args[0], int(float(args[1])), args[2], float(args[3]))
