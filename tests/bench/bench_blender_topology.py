"""In-Blender benchmark: the Topology panel's Analyse and Find Handles & Tunnels on ~100k-triangle
meshes, next to GUDHI's Betti numbers and Blender's 3D-Print Toolbox checks in the same run.

    blender -b --factory-startup --python tests/bench/bench_blender_topology.py -- [--repeat 3]
        [--mesh PATH:LEVELS ...]

Default meshes are genus-g models from tests/data subdivided to about 100k triangles (Loop
subdivision from ../shared/tools/loop_subdiv.py when present, else midpoint subdivision, which
keeps the shape and the topology). Times are those of the operators as a user runs them: read
the Blender mesh, compute, store the results on the object (Analyse also the generator edges).
Prints medians, ratios and the machine.
"""

import argparse
import os
import pathlib
import platform
import statistics
import sys
import time

import addon_utils
import bpy
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
SHARED_TOOLS = ROOT.parent / "shared" / "tools"
DEFAULT_MESHES = ("genus_positive/cgal_turbine.off:1", "genus_positive/cgal_elephant.off:2",
                  "genus_positive/cgal_knot1.off:2", "genus_positive/cgal_anchor_dense.off:2")


def subdivide(vertices, triangles, levels):
    """Loop subdivision when the shared tool is there (smooth surface), else midpoint."""
    if levels == 0:
        return vertices, triangles, "none"
    if (SHARED_TOOLS / "loop_subdiv.py").exists():
        sys.path.insert(0, str(SHARED_TOOLS))
        import loop_subdiv

        v, t = np.asarray(vertices, dtype=float), np.asarray(triangles, dtype=np.int64)
        for _ in range(levels):
            v, t = loop_subdiv.loop_once(v, t)
        return v, np.asarray(t, dtype=np.int32), f"Loop x{levels}"
    sys.path.insert(0, str(ROOT / "tests"))
    import meshgen

    v, t = meshgen.subdivide(vertices, triangles, levels)
    return v, t, f"midpoint x{levels}"


def timed(function, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def gudhi_betti(triangles):
    """Betti numbers through GUDHI's simplex tree (the peer in PEERS.md), or None."""
    try:
        import gudhi
    except ImportError:
        return None
    tree = gudhi.SimplexTree()
    for triangle in np.asarray(triangles).tolist():
        tree.insert(triangle)
    tree.compute_persistence(persistence_dim_max=True)
    return tree.betti_numbers()


def print3d_checks(obj):
    """Blender's 3D-Print Toolbox 'Solid' check (non-manifold edges, bad contiguity), or None."""
    try:
        addon_utils.enable("object_print3d_utils", default_set=True)
        bpy.ops.mesh.print3d_check_solid()
        return True
    except (AttributeError, RuntimeError):
        return None


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", nargs="+", default=list(DEFAULT_MESHES), help="PATH:LEVELS (relative to tests/data)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")),
               platform.processor())
    print(f"machine: {os.cpu_count()} cores, {cpu}; Blender {bpy.app.version_string}; "
          f"load average {os.getloadavg()[0]:.1f}")
    from topstoc.blender.io import mesh_write
    from topstoc.core.api import io

    for spec in args.mesh:
        path, _, levels = spec.partition(":")
        data = io.read_mesh(str(DATA / path) if not os.path.isabs(path) else path)
        vertices, triangles, how = subdivide(data.vertices, data.triangles, int(levels or 0))
        mesh = bpy.data.meshes.new(pathlib.Path(path).stem)
        mesh_write.fill_geometry(mesh, vertices, triangles)
        obj = bpy.data.objects.new(mesh.name, mesh)
        bpy.context.scene.collection.objects.link(obj)
        for other in bpy.context.scene.objects:
            other.select_set(False)
        obj.select_set(True)
        bpy.context.view_layer.objects.active = obj
        print(f"mesh: {path} ({how}): {len(vertices):,} vertices, {len(triangles):,} triangles")
        analyse = timed(lambda: bpy.ops.topstoc.analyse(), args.repeat)
        t = obj.topstoc.topology
        print(f"  Analyse (invariants + generator edges + panel data) {analyse * 1000:8.1f} ms (median of "
              f"{args.repeat}): {t.summary}")
        start = time.perf_counter()
        betti = gudhi_betti(triangles)
        gudhi_seconds = time.perf_counter() - start
        if betti is not None:
            print(f"  GUDHI Betti numbers (simplex tree + persistence)   {gudhi_seconds * 1000:8.1f} ms: {betti} "
                  f"(ours {[t.betti0, t.betti1, t.betti2]}); GUDHI / Analyse = {gudhi_seconds / analyse:.1f}x")
        start = time.perf_counter()
        if print3d_checks(obj):
            seconds = time.perf_counter() - start
            print(f"  3D-Print Toolbox 'Solid' check (no genus, no loops) {seconds * 1000:8.1f} ms; "
                  f"toolbox / Analyse = {seconds / analyse:.1f}x")
        search = timed(lambda: bpy.ops.topstoc.find_loops(), args.repeat)
        print(f"  Find Handles & Tunnels {search:8.2f} s (median of {args.repeat}): {t.loops_message}")
    print(f"load average after the run: {os.getloadavg()[0]:.1f} (on {os.cpu_count()} cores)")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python"))
    addon_utils.enable("topstoc", default_set=True)
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    code = main(argv)
    sys.stdout.flush()
    os._exit(code)
