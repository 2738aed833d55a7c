"""Benchmark: the add-on's reads and writes of Blender data against Blender's per-element accessors.

    blender -b --factory-startup --python tests/bench/bench_blender_io.py
    python tests/bench/bench_blender_io.py          # with PyPI's bpy module (4.2+)

On the 1.55M-triangle horse (../shared/meshes/big, skipped when absent), given a UV map, a
byte colour per corner and shape keys, each row times one mesh_io / carry function and, in the
same run, the foreach_get / foreach_set call through the per-element property it replaces
(MeshVertex.co, MeshUVLoop.uv, ByteColorAttributeValue.color_srgb, ShapeKeyPoint.co, MeshLoop
.vertex_index), checks that both give the same values, and prints the ratio. Medians of 5. The
last row writes a topology edit back (Delete Faces) against Blender's own Edit Mode delete.
"""

import os
import pathlib
import statistics
import sys
import time

import bpy  # first: PyPI's bpy module makes addon_utils importable
import addon_utils  # noqa: E402
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
HORSE = ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply"
REPEAT = 5
SHAPE_KEYS = 5


def median_seconds(function):
    times = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def per_element(collection, key, count, width, dtype=np.float32):
    """What a script without the add-on's shortcuts does: one foreach_get of an RNA property
    (index fields into a uint32 buffer, which takes foreach_get's raw-copy path in 3.x)."""
    buffer = np.empty(count * width, dtype=dtype)
    collection.foreach_get(key, buffer)
    return buffer.reshape(count, width)


def row(name, ours, peer, check):
    ours_seconds, peer_seconds = median_seconds(ours), median_seconds(peer)
    np.testing.assert_array_equal(*check())
    print(f"  {name:44s} {ours_seconds * 1000:8.1f} ms   per element {peer_seconds * 1000:8.1f} ms   "
          f"{peer_seconds / ours_seconds:6.1f}x")


def main():
    if not HORSE.exists():
        print(f"skipped: {HORSE} is not available")
        return 0
    io = ts.blender.io
    mesh_read, mesh_write, mesh_attributes, carry = io.mesh_read, io.mesh_write, io.mesh_attributes, io.carry
    data = ts.core.api.io.read_mesh(str(HORSE))
    mesh = bpy.data.meshes.new("Horse")
    mesh_write.fill_geometry(mesh, data.vertices, data.triangles)
    obj = bpy.data.objects.new("Horse", mesh)
    bpy.context.scene.collection.objects.link(obj)
    n, corners = len(mesh.vertices), len(mesh.loops)
    rng = np.random.default_rng(1)
    mesh.uv_layers.new(name="UV")
    mesh.uv_layers["UV"].data.foreach_set("uv", rng.random(2 * corners).astype(np.float32))
    mesh.color_attributes.new("Paint", "BYTE_COLOR", "CORNER")
    paint = mesh.color_attributes["Paint"]
    paint.data.foreach_set("color_srgb", (rng.integers(0, 256, 4 * corners) / 255).astype(np.float32))
    obj.shape_key_add(name="Basis")
    for k in range(SHAPE_KEYS - 1):
        block = obj.shape_key_add(name=f"Key{k}", from_mix=False)
        block.data.foreach_set("co", (data.vertices + rng.normal(0, 0.01, data.vertices.shape)).astype(np.float32).ravel())
    blocks = mesh.shape_keys.key_blocks

    print(f"machine: {machine()}; Blender {bpy.app.version_string}")
    print(f"mesh: {HORSE.name} ({n:,} vertices, {corners:,} corners), a UV map, a byte colour per corner, "
          f"{SHAPE_KEYS} shape keys")
    row("positions (read_positions)", lambda: mesh_read.read_positions(mesh),
        lambda: per_element(mesh.vertices, "co", n, 3),
        lambda: (mesh_read.read_positions(mesh), per_element(mesh.vertices, "co", n, 3)))
    row("corner vertices (corner_vertices)", lambda: mesh_read.corner_vertices(mesh),
        lambda: per_element(mesh.loops, "vertex_index", corners, 1, np.uint32),
        lambda: (mesh_read.corner_vertices(mesh), per_element(mesh.loops, "vertex_index", corners, 1, np.uint32)[:, 0]))
    row("the mesh as the engine takes it (read_mesh)", lambda: mesh_read.read_mesh(mesh),
        lambda: (per_element(mesh.vertices, "co", n, 3), per_element(mesh.loops, "vertex_index", corners, 1, np.uint32),
                 per_element(mesh.polygons, "loop_start", len(mesh.polygons), 1, np.uint32)),
        lambda: (mesh_read.read_mesh(mesh).triangles.ravel(),
                 per_element(mesh.loops, "vertex_index", corners, 1, np.uint32)[:, 0]))
    row("a UV map (read_uv_map)", lambda: mesh_attributes.read_uv_map(mesh, "UV"),
        lambda: per_element(mesh.uv_layers["UV"].data, "uv", corners, 2),
        lambda: (mesh_attributes.read_uv_map(mesh, "UV"), per_element(mesh.uv_layers["UV"].data, "uv", corners, 2)))
    row("a byte colour per corner (read_attribute)", lambda: mesh_attributes.read_attribute(paint, corners),
        lambda: per_element(paint.data, "color_srgb", corners, 4),
        lambda: (mesh_attributes.read_attribute(paint, corners)[0], per_element(paint.data, "color_srgb", corners, 4)))
    row(f"{SHAPE_KEYS} shape keys (read_shape_keys)", lambda: carry.read_shape_keys(mesh),
        lambda: [per_element(block.data, "co", n, 3) for block in blocks],
        lambda: (np.stack(carry.read_shape_keys(mesh).coordinates).astype(np.float32),
                 np.stack([per_element(block.data, "co", n, 3) for block in blocks])))
    out = bpy.data.meshes.new("Written")
    out.vertices.add(n)
    row("write positions (write_positions)", lambda: mesh_write.write_positions(out, data.vertices),
        lambda: out.vertices.foreach_set("co", data.vertices.astype(np.float32).ravel()),
        lambda: (mesh_read.read_positions(out), data.vertices.astype(np.float32)))
    edit_row(data)
    return 0


def edit_row(data):
    """Delete 200 faces of the horse: TopStoc's Delete Faces operator (read, engine edit, write
    the mesh back with its attributes and flags, re-analyse) against Blender's own Edit Mode
    delete, mode switches included (what an artist would otherwise do). One run each, fresh
    objects with a vertex group on a third of the vertices."""
    times = {}
    for kind in ("topstoc", "blender"):
        mesh = bpy.data.meshes.new(kind)
        ts.blender.io.mesh_write.fill_geometry(mesh, data.vertices, data.triangles)
        obj = bpy.data.objects.new(kind, mesh)
        bpy.context.scene.collection.objects.link(obj)
        group = obj.vertex_groups.new(name="Group")
        group.add(list(range(0, len(mesh.vertices), 3)), 0.5, "REPLACE")
        for other in bpy.context.scene.objects:
            other.select_set(other is obj)
        bpy.context.view_layer.objects.active = obj
        chosen = np.zeros(len(mesh.polygons), dtype=bool)
        chosen[:200] = True
        mesh.vertices.foreach_set("select", np.zeros(len(mesh.vertices), dtype=bool))
        mesh.edges.foreach_set("select", np.zeros(len(mesh.edges), dtype=bool))
        mesh.polygons.foreach_set("select", chosen)
        start = time.perf_counter()
        if kind == "topstoc":
            assert bpy.ops.topstoc.delete_faces() == {"FINISHED"}
        else:
            bpy.context.tool_settings.mesh_select_mode = (False, False, True)
            bpy.ops.object.mode_set(mode="EDIT")
            bpy.ops.mesh.delete(type="FACE")
            bpy.ops.object.mode_set(mode="OBJECT")
        times[kind] = time.perf_counter() - start
        assert len(obj.data.polygons) == len(data.triangles) - 200, (kind, len(obj.data.polygons))
        bpy.data.objects.remove(obj)
    print(f"  {'delete 200 faces (Delete Faces operator)':44s} {times['topstoc'] * 1000:8.1f} ms   "
          f"Edit Mode delete {times['blender'] * 1000:8.1f} ms   {times['blender'] / times['topstoc']:6.2f}x (one run)")


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python"))
    addon_utils.enable("topstoc", default_set=True)
    import topstoc as ts  # noqa: E402
    import topstoc.blender.io.carry  # noqa: E402,F401
    import topstoc.blender.io.mesh_read  # noqa: E402,F401
    import topstoc.blender.io.mesh_write  # noqa: E402,F401
    import topstoc.blender.io.mesh_attributes  # noqa: E402,F401

    code = main()
    sys.stdout.flush()
    os._exit(code)
