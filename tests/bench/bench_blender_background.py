"""In-Blender benchmark: Guided Decimate's modal run (decimation/background.py) on a big mesh,
and the add-on's Max Deviation against a ratio target at the same result size.

    .venv/bin/python tests/bench/bench_blender_background.py -- [--triangles 20000000] [--ratio 0.01]
    .venv/bin/python tests/bench/bench_blender_background.py -- --mesh PATH --max-error 0.3

Long run (a generated bumpy torus): the main thread's seconds at invoke (reading the mesh and its
guidance) and at the end (writing the result), the worker's seconds, the longest gap between two
polls of a 10 Hz loop while the worker runs (what the modal's timer would see: the interface's
longest stall), and the seconds from a cancel during the preparation to the worker's end.
Max Deviation: seconds of the error target on the worker, next to a ratio target giving the same
vertex count (both prepared beforehand), with the probes the search made.
"""

import argparse
import os
import pathlib
import sys
import time

import bpy  # first: PyPI's bpy module makes addon_utils importable
import addon_utils  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


class Params:
    def __init__(self, **values):
        self.target_mode, self.ratio, self.seed, self.adaptivity, self.density = "RATIO", 0.01, 1, 0.5, "off"
        self.quality, self.placement, self.refine, self.output = "QUALITY", "subsample", 0, "NEW_OBJECT"
        self.vertices = self.triangles = 1
        self.max_error, self.max_error_relative = 0.0, True
        self.__dict__.update(values)


def make_object(name, vertices, triangles):
    mesh = bpy.data.meshes.new(name)
    ts.blender.io.mesh_write.fill_geometry(mesh, vertices, triangles)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def run_polled(job, poll=0.1):
    """Polls ``job`` like the modal's timer; (seconds until finished, longest gap between polls)."""
    start = last = time.perf_counter()
    longest = 0.0
    while not job.finished():
        time.sleep(poll)
        now = time.perf_counter()
        longest, last = max(longest, now - last - poll), now
        job.progress()
    return time.perf_counter() - start, longest


def long_run(obj, ratio):
    background, pipeline = ts.blender.decimation.background, ts.blender.decimation.pipeline
    ts.blender.preview.cache.prepared_meshes.clear()
    clock = time.perf_counter()
    reads = [pipeline.read_input(bpy.context, obj, Params(ratio=ratio))]
    read = time.perf_counter() - clock
    job = background.BackgroundDecimation(reads)
    worker, stall = run_polled(job)
    run, failure = job.outcomes[0]
    assert failure is None, failure
    clock = time.perf_counter()
    out = pipeline.write_output(run)
    write = time.perf_counter() - clock
    bpy.data.objects.remove(out)
    print(f"  main thread: read {read:.2f} s at invoke, write {write:.2f} s at the end; worker {worker:.2f} s "
          f"(prepare + decimate, {run.result.num_vertices:,} vertices); longest stall of a 10 Hz poll "
          f"meanwhile {stall:.3f} s", flush=True)
    ts.blender.preview.cache.prepared_meshes.clear()
    job = background.BackgroundDecimation([pipeline.read_input(bpy.context, obj, Params(ratio=ratio))])
    time.sleep(min(2.0, worker / 4))
    line = job.progress()[1]
    clock = time.perf_counter()
    job.cancel()
    job.wait()
    print(f"  cancel during '{line}': the worker ended {time.perf_counter() - clock:.2f} s later, "
          f"{len(job.outcomes)} results", flush=True)


def max_deviation(obj, max_error, quality):
    background, pipeline = ts.blender.decimation.background, ts.blender.decimation.pipeline
    pipeline.prepare(obj)  # both targets start from the prepared mesh

    def timed(**values):
        job = background.BackgroundDecimation([pipeline.read_input(bpy.context, obj, Params(quality=quality,
                                                                                             **values))])
        clock = time.perf_counter()
        job.wait()
        return time.perf_counter() - clock, job.outcomes[0][0].result

    seconds, result = timed(target_mode="MAX_ERROR", max_error=max_error)
    ratio_seconds, same = timed(target_mode="VERTICES", vertices=result.num_vertices)
    probes = len(result.error_bound.probes) if result.error_bound is not None else 0
    print(f"  {quality}: Max Deviation {max_error} % -> {result.num_vertices:,} vertices in {seconds:.2f} s "
          f"({probes} probes); the same count as a target {ratio_seconds:.2f} s ({same.num_vertices:,} vertices): "
          f"{seconds / ratio_seconds:.1f}x (goal <= 3x)", flush=True)


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--triangles", type=int, default=2_000_000)
    parser.add_argument("--ratio", type=float, default=0.01)
    parser.add_argument("--mesh", help="a mesh file for --max-error (default: the generated torus)")
    parser.add_argument("--max-error", type=float, help="percent of the diagonal: time Max Deviation instead")
    args = parser.parse_args(argv)
    print(f"machine: {os.cpu_count()} cores; Blender {bpy.app.version_string}; load average "
          f"{os.getloadavg()[0]:.1f}", flush=True)
    if args.mesh:
        data = ts.core.api.io.read_mesh(args.mesh)
        vertices, triangles, name = data.vertices, data.triangles, pathlib.Path(args.mesh).name
    else:
        sys.path.insert(0, str(ROOT / "tests"))
        import meshgen
        vertices, triangles = meshgen.bumpy_torus(args.triangles)
        name = "bumpy torus"
    obj = make_object("Big", vertices, triangles)
    del vertices, triangles
    print(f"mesh: {name}, {len(obj.data.polygons):,} triangles", flush=True)
    if args.max_error is None:
        long_run(obj, args.ratio)
    else:
        for quality in ("FAST", "QUALITY"):
            max_deviation(obj, args.max_error, quality)
    print(f"load average after the run: {os.getloadavg()[0]:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python"))
    addon_utils.enable("topstoc", default_set=True)
    import topstoc as ts  # noqa: E402
    import topstoc.blender.decimation.background  # noqa: E402,F401
    import topstoc.core.api.io  # noqa: E402,F401

    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    code = main(argv)
    sys.stdout.flush()
    os._exit(code)
