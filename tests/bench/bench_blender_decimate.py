"""In-Blender benchmark: TopStoc Guided Decimate vs Blender's Decimate modifier (Collapse).

    blender -b --factory-startup --python tests/bench/bench_blender_decimate.py -- [--ratios 0.01 0.1]
        [--mesh PATH] [--repeat 3] [--updates 20]
    .venv/bin/python tests/bench/bench_blender_decimate.py -- ...   (PyPI's bpy)
    ... -- --only-rest --mesh bumpy_torus:150000 --json docs/bench_results/bench_blender_rest.json --label after

``--mesh`` also takes ``bumpy_torus:TRIANGLES`` (tests/meshgen.py). With ``--only-rest --json FILE
--label NAME`` the rest figures are merged into FILE under NAME per mesh and ratio, so that runs of
two builds (TOPSTOC_BUILD) alternating one mesh at a time fill one table.

On the 1.55M-triangle horse (../shared/meshes/big, skipped when absent): time to first result
(read the Blender mesh + prepare + decimate + write the new object with attributes) and the time
of one live-preview update (re-decimate the cached mesh + write the preview mesh), next to the
Decimate modifier applied at the same ratio in the same run, the rate of updates shown
during a simulated drag of the modal slider, the Live Preview's start (control back to the
user, first result shown) on an unprepared and a prepared mesh, its Enter with Quality chosen
(main-thread seconds before and now), and the time from a drag resting to the rested Quality
result on screen. Prints medians and ratios.
"""

import argparse
import json
import os
import pathlib
import platform
import statistics
import sys
import time

import bpy  # first: PyPI's bpy module makes addon_utils importable
import addon_utils  # noqa: E402
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "bench")]
import meshgen  # noqa: E402
from machine import save_figures  # noqa: E402

HORSE = ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply"


def read_binary_ply(path):
    """Vertices and triangles of a binary little-endian PLY with float xyz and uchar/int lists."""
    with open(path, "rb") as stream:
        header = []
        while True:
            line = stream.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        body = stream.read()
    counts = {l.split()[1]: int(l.split()[2]) for l in header if l.startswith("element")}
    if "format binary_little_endian 1.0" not in header or "property list uchar int vertex_indices" not in header:
        raise ValueError(f"{path}: only the plain binary layout of the benchmark mesh is supported")
    n, m = counts["vertex"], counts["face"]
    vertices = np.frombuffer(body, dtype="<f4", count=3 * n).reshape(n, 3)
    faces = np.frombuffer(body, dtype=np.dtype([("k", "u1"), ("v", "<i4", 3)]), count=m, offset=12 * n)
    if np.any(faces["k"] != 3):
        raise ValueError(f"{path}: not a triangle mesh")
    return vertices.astype(np.float64), faces["v"].astype(np.int32)


def make_object(name, vertices, triangles):
    mesh = bpy.data.meshes.new(name)
    ts.blender.io.mesh_write.fill_geometry(mesh, vertices, triangles)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


class Params:
    def __init__(self, ratio, quality="CUSTOM"):
        self.quality = quality  # CUSTOM: the placement and refine below (fast mode)
        self.target_mode, self.ratio, self.seed, self.adaptivity = "RATIO", ratio, 1, 0.5
        self.density, self.placement, self.refine, self.output = "off", "subsample", 0, "NEW_OBJECT"
        self.vertices = self.triangles = 1
        self.max_error, self.max_error_relative = 0.0, False


def remove(obj):
    mesh = obj.data
    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(mesh)


def topstoc_first_result(obj, ratio):
    """Seconds of one cold Guided Decimate (cache emptied): read + prepare + decimate + write."""
    pipeline = ts.blender.decimation.pipeline
    ts.blender.preview.cache.prepared_meshes.clear()
    start = time.perf_counter()
    run = pipeline.decimate(bpy.context, obj, Params(ratio))
    out = pipeline.write_output(run)
    seconds = time.perf_counter() - start
    counts = (len(out.data.vertices), len(out.data.polygons))
    remove(out)
    return seconds, counts


def stages(obj, ratio):
    """The same work stage by stage (one run): where the first result's time goes."""
    mesh_read, mesh_write, t = ts.blender.io.mesh_read, ts.blender.io.mesh_write, {}
    clock = time.perf_counter()
    arrays = mesh_read.read_mesh(obj.data)
    t["read"], clock = time.perf_counter() - clock, time.perf_counter()
    arrays.digest()
    t["fingerprint"], clock = time.perf_counter() - clock, time.perf_counter()
    mesh = ts.core.Mesh(arrays.vertices, arrays.triangles)
    t["prepare"], clock = time.perf_counter() - clock, time.perf_counter()
    mesh.feature_layout(None, None)
    t["layout"], clock = time.perf_counter() - clock, time.perf_counter()
    result = mesh.decimate(ratio=ratio, seed=1, mode="fast")  # as the first result (Params: fast)
    t["decimate"], clock = time.perf_counter() - clock, time.perf_counter()
    written = bpy.data.meshes.new("stage")
    mesh_write.fill_geometry(written, result.vertices, result.triangles)
    t["write geometry"] = time.perf_counter() - clock
    bpy.data.meshes.remove(written)
    return t


def preview_updates(obj, ratio, count):
    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, Params(ratio))
    session.update(ratio)  # warm
    times = []
    for r in np.geomspace(ratio / 2, min(1.0, ratio * 2), count):
        start = time.perf_counter()
        session.update(float(r))
        times.append(time.perf_counter() - start)
    decimate_part = session.seconds_decimate
    session.close()
    return times, decimate_part


def preview_start(obj, ratio, prepared):
    """Live Preview start the way the operator's invoke runs it: seconds until control returns
    (the session read the mesh and its guidance and handed the rest to a worker; the modal then
    runs and shows the preparation's progress), the main thread's CPU seconds in that time (what
    other processes' load does not inflate), and seconds until the first result is shown (polled
    every 5 ms; the modal timer polls at 60 Hz). ``prepared``: the mesh is in the cache already."""
    if not prepared:
        ts.blender.preview.cache.prepared_meshes.clear()
    start, cpu = time.perf_counter(), time.thread_time()
    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, Params(ratio), ratio=ratio)
    control, cpu = time.perf_counter() - start, time.thread_time() - cpu
    while not session.poll():
        time.sleep(0.005)
    first = time.perf_counter() - start
    session.close()
    return control, cpu, first


def preview_drag(obj, ratio, seconds=4.0, event_interval=0.01, span=2.0):
    """Updates shown per second during a drag, the way the modal slider runs: a new ratio is
    requested every ``event_interval`` (mouse events), the worker thread decimates the latest
    request while the main thread writes the previous result into the preview object. The
    ratios go back and forth over [ratio / span, ratio * span] in 50 events (0.5 s): span 2 is
    a sweep over a factor of four, span 1.1 a fine adjustment around the ratio (0.4 % a step),
    where nearby requests update each other's floods (native flood_cache.hpp)."""
    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, Params(ratio))
    session.update(ratio)  # warm
    sweep = np.geomspace(ratio / span, min(1.0, ratio * span), 50)
    shown, start, i = 0, time.perf_counter(), 0
    while time.perf_counter() - start < seconds:
        session.request(float(sweep[i % len(sweep)] if (i // len(sweep)) % 2 == 0 else sweep[-1 - i % len(sweep)]))
        i += 1
        if session.poll():
            shown += 1
        time.sleep(event_interval)
    elapsed = time.perf_counter() - start
    session.close()
    return shown / elapsed


def rested_quality(obj, ratio, drag_seconds=1.0, event_interval=0.01, cold=False):
    """Seconds from the drag resting (the last ratio requested) to the rested Quality result on
    screen, the way the modal runs it (requests every 10 ms over [ratio / 1.5, ratio], then
    polling at the modal timer's 60 Hz), the seconds of that Quality computation itself, and the
    updates shown per second during the drag. cold: the prepared mesh keeps nothing from earlier
    decimations when the drag starts (else a repeat finds what the one before kept)."""
    if cold:
        ts.blender.preview.cache.prepared_meshes.clear_kept()
    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, Params(ratio, quality="QUALITY"), ratio=ratio)
    session.wait_prepared()
    sweep = np.geomspace(ratio / 1.5, ratio, 40)
    start, i, shown = time.perf_counter(), 0, 0
    while time.perf_counter() - start < drag_seconds:
        session.request(float(sweep[i % len(sweep)]))
        i += 1
        shown += session.poll()
        time.sleep(event_interval)
    rate = shown / (time.perf_counter() - start)
    session.request(ratio)  # the drag rests here
    rested = time.perf_counter()
    while not (session.final and session.ratio == ratio):
        session.poll()
        time.sleep(1 / 60)
    seconds = time.perf_counter() - rested
    computed = session.final_seconds
    session.close()
    return seconds, computed, rate


def preview_apply(obj, ratio):
    """Live Preview's Enter with Quality chosen, main-thread seconds (what freezes the interface):
    (before: decimating again at Quality on the main thread, then writing; now, a rested result:
    writing the Quality result on screen; now, Enter during the drag: seconds until written, the
    main thread only polling meanwhile, and its busy part: apply, polls and the write)."""
    pipeline, params = ts.blender.decimation.pipeline, Params(ratio, quality="QUALITY")
    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, params, ratio=ratio)
    while not session.final:  # the fast result, then the rested Quality one
        session.poll()
        time.sleep(0.005)
    start = time.perf_counter()
    out = pipeline.write_output(pipeline.decimate(bpy.context, obj, params))
    before = time.perf_counter() - start
    remove(out)
    rested, _, out = applied(session, ratio)
    remove(out)
    dragged, busy, out = applied(session, ratio * 1.1)
    remove(out)
    session.close()
    return before, rested, dragged, busy


def applied(session, ratio):
    """Enter at ``ratio`` the way the modal runs it: apply, then poll at the modal timer's rate
    until the Run is ready (a rested result's attribute sources may still be found on a worker),
    then write. Seconds until written, the main thread's busy part of them, and the output object."""
    start = time.perf_counter()
    run, busy = session.apply(ratio), time.perf_counter() - start
    while run is None:
        time.sleep(1 / 60)  # the modal timer
        clock = time.perf_counter()
        run = session.poll_apply()
        busy += time.perf_counter() - clock
    clock = time.perf_counter()
    out = ts.blender.decimation.pipeline.write_output(run)
    busy += time.perf_counter() - clock
    return time.perf_counter() - start, busy, out


def print_rest(ratio, rests):
    rest, computed, rate = (statistics.median(r[i] for r in rests) for i in range(3))
    print(f"  ratio {ratio}: Live Preview, drag rested -> Quality result shown: {rest:.3f} s (its computation "
          f"{computed:.3f} s; medians of {len(rests)}, max {max(r[0] for r in rests):.3f} s; goal <= 0.3 s up to "
          f"200k triangles, <= 1 s on the horse); {rate:.1f} updates shown per second during the drag")
    return {"ratio": ratio, "rest_s": rest, "rest_max_s": max(r[0] for r in rests), "computed_s": computed,
            "drag_updates_per_s": rate, "repeats": len(rests), "load_average": os.getloadavg()[0]}


REST_METHOD = ("a PreviewSession with Quality chosen, after a 1 s drag (--drag; a ratio requested every 10 ms over "
               "[ratio / 1.5, ratio]): seconds from the last request to the Quality result on screen (polled at "
               "60 Hz), medians of the repeats; builds alternate one mesh at a time (TOPSTOC_BUILD); a label "
               "with 'cold' (--cold): each drag starts with nothing kept from earlier decimations of the mesh")


def save_rest(path, label, mesh, counts, rows):
    """Merges one build's rest figures (``label``) for one mesh into the JSON file at ``path``."""
    figures = json.loads(pathlib.Path(path).read_text()) if os.path.exists(path) else {"meshes": []}
    entry = next((m for m in figures["meshes"] if m["mesh"] == mesh), None)
    if entry is None:
        entry = {"mesh": mesh, "vertices": counts[0], "triangles": counts[1], "ratios": {}}
        figures["meshes"].append(entry)
    for row in rows:
        entry["ratios"].setdefault(str(row["ratio"]), {})[label] = row
    save_figures(path, "tests/bench/bench_blender_decimate.py --only-rest", REST_METHOD,
                 blender=bpy.app.version_string, meshes=figures["meshes"])


def subdivided(vertices, triangles):
    """Every triangle split in four at its edges' midpoints (a bigger mesh of the same shape)."""
    triangles = np.asarray(triangles, dtype=np.int64)
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    unique, index = np.unique(edges, axis=0, return_inverse=True)
    index = index.ravel() + len(vertices)
    count = len(triangles)
    a, b, c = index[:count], index[count:2 * count], index[2 * count:]
    t0, t1, t2 = triangles.T
    split = np.concatenate([np.stack(corners, axis=1) for corners in ((t0, a, c), (t1, b, a), (t2, c, b), (a, b, c))])
    midpoints = (vertices[unique[:, 0]] + vertices[unique[:, 1]]) / 2
    return np.concatenate([vertices, midpoints]), split.astype(np.int32)


def modifier_apply(obj, ratio):
    copy = obj.copy()
    copy.data = obj.data.copy()
    bpy.context.scene.collection.objects.link(copy)
    modifier = copy.modifiers.new("Decimate", "DECIMATE")
    modifier.decimate_type = "COLLAPSE"
    modifier.ratio = ratio
    for other in bpy.context.scene.objects:
        other.select_set(False)
    copy.select_set(True)
    bpy.context.view_layer.objects.active = copy
    start = time.perf_counter()
    bpy.ops.object.modifier_apply(modifier="Decimate")
    seconds = time.perf_counter() - start
    counts = (len(copy.data.vertices), len(copy.data.polygons))
    remove(copy)
    return seconds, counts


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", default=str(HORSE))
    parser.add_argument("--ratios", type=float, nargs="+", default=[0.01, 0.1])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--updates", type=int, default=20)
    parser.add_argument("--modifier-repeat", type=int, default=1)
    parser.add_argument("--only-rest", action="store_true", help="measure only the rested Quality result")
    parser.add_argument("--subdivide", type=int, default=0, help="split every triangle in four this many times")
    parser.add_argument("--cold", action="store_true",
                        help="with --only-rest: each drag starts with nothing kept from earlier decimations")
    parser.add_argument("--drag", type=float, default=1.0, help="with --only-rest: seconds of the drag before the rest")
    parser.add_argument("--json", metavar="FILE", help="with --only-rest: merge the rest figures into this file")
    parser.add_argument("--label", default="after", help="the build's name in --json (before, after)")
    args = parser.parse_args(argv)
    generated = args.mesh.startswith("bumpy_torus:")
    if not generated and not os.path.exists(args.mesh):
        print(f"skipped: {args.mesh} is not available")
        return 0
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")),
               platform.processor())
    print(f"machine: {os.cpu_count()} cores, {cpu}; Blender {bpy.app.version_string}; "
          f"load average {os.getloadavg()[0]:.1f}; OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY', 'default')}")
    vertices, triangles = read_input(args.mesh)
    for _ in range(args.subdivide):
        vertices, triangles = subdivided(vertices, triangles)
    obj = make_object("Horse", vertices, triangles)
    print(f"mesh: {args.mesh} ({len(vertices):,} vertices, {len(triangles):,} triangles); "
          f"add-on from {pathlib.Path(ts.__file__).parent}")
    rest_rows = []
    for ratio in args.ratios:
        if args.only_rest:
            rest_rows.append(print_rest(ratio, [rested_quality(obj, ratio, args.drag, cold=args.cold)
                                                    for _ in range(args.repeat)]))
            continue
        firsts = []
        for _ in range(args.repeat):
            seconds, ours = topstoc_first_result(obj, ratio)
            firsts.append(seconds)
        split = stages(obj, ratio)
        updates, _ = preview_updates(obj, ratio, args.updates)
        drag_rate = preview_drag(obj, ratio)
        fine_rate = preview_drag(obj, ratio, span=1.1)
        starts = {kind: [preview_start(obj, ratio, kind == "prepared") for _ in range(args.repeat)]
                  for kind in ("unprepared", "prepared")}
        applies = [preview_apply(obj, ratio) for _ in range(args.repeat)]
        rests = [rested_quality(obj, ratio) for _ in range(args.repeat)]
        modifier = [modifier_apply(obj, ratio) for _ in range(args.modifier_repeat)]
        first = statistics.median(firsts)
        update = statistics.median(updates)
        print(f"target ratio {ratio}:")
        print(f"  TopStoc first result  {first:8.3f} s  (median of {args.repeat})  -> {ours[0]:,} v, {ours[1]:,} t")
        print("    stages of one run: " + ", ".join(f"{k} {v:.3f} s" for k, v in split.items()))
        print(f"  TopStoc slider update {update * 1000:8.1f} ms (median of {len(updates)} ratios in "
              f"[{ratio / 2:g}, {min(1, 2 * ratio):g}]; max {max(updates) * 1000:.1f} ms) "
              f"= {1 / update:.1f} updates/s one after another")
        for kind, runs in starts.items():
            goal = 0.5 if kind == "unprepared" else 0.1
            control, cpu, shown = (statistics.median(run[i] for run in runs) for i in range(3))
            print(f"  Live Preview start, {kind:10s}: control back (progress shown) after {control * 1000:6.1f} ms, "
                  f"{cpu * 1000:5.1f} ms of it main-thread CPU (goal <= {goal * 1000:.0f} ms); first result shown "
                  f"after {shown * 1000:7.1f} ms (medians of {len(runs)})")
        print(f"  TopStoc slider drag    {drag_rate:8.1f} updates shown per second (modal path: a ratio "
              f"requested every 10 ms, decimation on a worker thread while the main thread writes; "
              f"sweep over [{ratio / 2:g}, {min(1, 2 * ratio):g}] and back every second)")
        print(f"  TopStoc slider drag    {fine_rate:8.1f} updates shown per second (the same, fine adjustment "
              f"over [{ratio / 1.1:.4g}, {min(1, 1.1 * ratio):.4g}]: nearby requests update kept floods)")
        before, rested, dragged, busy = (statistics.median(a[i] for a in applies) for i in range(4))
        print(f"  Live Preview Enter (Quality): before {before:.3f} s on the main thread (decimate again + write); "
              f"now {rested:.3f} s for a rested result (write only, {before / rested:.1f}x less), during a drag "
              f"{dragged:.3f} s until written with {busy:.3f} s of it on the main thread (medians of {len(applies)})")
        print_rest(ratio, rests)
        if modifier:
            mod_seconds = statistics.median(s for s, _ in modifier)
            print(f"  Blender Decimate modifier (Collapse) apply {mod_seconds:8.3f} s (median of "
                  f"{len(modifier)}) -> {modifier[0][1][0]:,} v, {modifier[0][1][1]:,} t")
            print(f"  ratio modifier / TopStoc first result: {mod_seconds / first:.1f}x; "
                  f"modifier / slider update: {mod_seconds / update:.0f}x")
    if args.json and rest_rows:
        name = pathlib.Path(args.mesh).name + (f", subdivided {args.subdivide}x" if args.subdivide else "")
        save_rest(args.json, args.label, name, (len(vertices), len(triangles)), rest_rows)
    print(f"load average after the run: {os.getloadavg()[0]:.1f} (on {os.cpu_count()} cores)")
    return 0


def read_input(spec):
    """Vertices and triangles of a mesh file, or of ``bumpy_torus:TRIANGLES`` (tests/meshgen.py)."""
    if spec.startswith("bumpy_torus:"):
        return meshgen.bumpy_torus(int(float(spec.split(":", 1)[1])))
    try:
        from topstoc.core.api.io import read_mesh  # any format when the io module is built
        data = read_mesh(spec)
        return data.vertices, data.triangles
    except ImportError:
        return read_binary_ply(spec)


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python"))
    addon_utils.enable("topstoc", default_set=True)
    import topstoc as ts  # noqa: E402
    import topstoc.blender.decimation.pipeline  # noqa: E402,F401
    import topstoc.blender.preview.session  # noqa: E402,F401

    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    code = main(argv)
    sys.stdout.flush()
    os._exit(code)
