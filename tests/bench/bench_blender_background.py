"""In-Blender benchmark: Guided Decimate's modal run (decimation/background.py) on a big mesh,
and the add-on's Max Deviation against a ratio target at the same result size.

    .venv/bin/python tests/bench/bench_blender_background.py -- [--triangles 20000000] [--ratio 0.01]
    .venv/bin/python tests/bench/bench_blender_background.py -- --mesh PATH --max-error 0.3
    .venv/bin/python tests/bench/bench_blender_background.py -- --memory --triangles 20000000 \
        [--json docs/bench_results/bench_blender_memory.json]

Long run (a generated bumpy torus): the main thread's seconds at invoke (reading the mesh and its
guidance) and at the end (writing the result), the worker's seconds, the longest gap between two
polls of a 10 Hz loop while the worker runs (what the modal's timer would see: the interface's
longest stall), and the seconds from a cancel during the preparation to the worker's end.
Max Deviation: seconds of the error target on the worker, next to a ratio target giving the same
vertex count (both prepared beforehand), with the probes the search made.
Memory (--memory): peak resident memory above Blender's own mesh per triangle, Guided Decimate's
worker path (read, prepare and decimate on the worker, write) next to the engine alone on the
arrays the add-on reads, each in a fresh process (tests/blender/memory_peak_script.py), both modes.
"""

import argparse
import json
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


def memory(triangles, ratio, path):
    """Peaks of the worker path and of the engine alone, each in a fresh process; saved to ``path``."""
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    from launch import background, clean_environment

    build = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python"
    rows = []
    for mode in ("QUALITY", "FAST"):
        row = {"mode": mode.lower()}
        for kind in ("addon", "engine"):
            done = background(ROOT / "tests" / "blender" / "memory_peak_script.py", kind, triangles, mode, ratio,
                              timeout=3600, env=clean_environment(TOPSTOC_BUILD_PYTHON=build))
            if done.returncode != 0:
                raise SystemExit(f"the {kind} run failed:\n{done.stderr[-2000:]}")
            row[kind] = json.loads(next(line for line in reversed(done.stdout.splitlines()) if line.startswith("{")))
        rows.append(row)
        addon, engine = row["addon"], row["engine"]
        print(f"  {mode}: {addon['triangles']:,} triangles, Guided Decimate {addon['bytes_per_triangle']:.1f} B/triangle "
              f"above Blender's mesh ({addon['seconds']:.1f} s), the engine alone {engine['bytes_per_triangle']:.1f} "
              f"({engine['seconds']:.1f} s): the add-on adds "
              f"{addon['bytes_per_triangle'] - engine['bytes_per_triangle']:.1f}", flush=True)
    if path:
        sys.path.insert(0, str(ROOT / "tests" / "bench"))
        from machine import save_figures

        save_figures(path, "tests/bench/bench_blender_background.py --memory",
                     "bumpy torus object from tests/meshgen.py, seed 1; each run in a fresh process: peak RSS above "
                     "the process after the object was made (Blender's own mesh in hand), per triangle; Guided "
                     "Decimate = read, prepare and decimate on the worker, moved sources, write as a new object; "
                     "engine alone = Mesh(...).decimate on the arrays the add-on reads",
                     blender=bpy.app.version_string, ratio=ratio, runs=rows)


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--triangles", type=int, default=2_000_000)
    parser.add_argument("--ratio", type=float, default=0.01)
    parser.add_argument("--mesh", help="a mesh file for --max-error (default: the generated torus)")
    parser.add_argument("--max-error", type=float, help="percent of the diagonal: time Max Deviation instead")
    parser.add_argument("--memory", action="store_true", help="peak memory of the worker path and of the engine")
    parser.add_argument("--json", metavar="FILE", help="with --memory: write the figures here")
    args = parser.parse_args(argv)
    print(f"machine: {os.cpu_count()} cores; Blender {bpy.app.version_string}; load average "
          f"{os.getloadavg()[0]:.1f}", flush=True)
    if args.memory:
        memory(args.triangles, args.ratio, args.json)
        return 0
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
