"""fill_geometry writes the engine's edges instead of asking Blender for them: the mesh must be
the one calc_edges would give (same edges, each loop's edge joining its face's corners), valid,
and editable (BMesh round trip, Edit Mode) in Blender 3.4 and 4.2."""

import bmesh
import bpy
import numpy as np

import meshgen
from helpers import select_only


def edge_pairs(mesh):
    pairs = np.empty(2 * len(mesh.edges), dtype=np.int32)
    mesh.edges.foreach_get("vertices", pairs)
    return np.sort(pairs.reshape(-1, 2), axis=1)


def loop_arrays(mesh):
    vertex, edge = (np.empty(len(mesh.loops), dtype=np.int32) for _ in range(2))
    mesh.loops.foreach_get("vertex_index", vertex)
    mesh.loops.foreach_get("edge_index", edge)
    return vertex, edge


def calc_edges_mesh(ts, vertices, triangles):
    """The same triangles with Blender deriving the edges (the previous write path)."""
    mesh = bpy.data.meshes.new("calc_edges")
    m = len(triangles)
    mesh.vertices.add(len(vertices))
    mesh.loops.add(3 * m)
    mesh.polygons.add(m)
    mesh.vertices.foreach_set("co", vertices.astype(np.float32).ravel())
    mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * m, 3, dtype=np.int32))
    if bpy.app.version < (4, 0, 0):
        mesh.polygons.foreach_set("loop_total", np.full(m, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    return mesh


def check_written(ts, vertices, triangles):
    mesh = bpy.data.meshes.new("written")
    ts.blender.io.mesh_write.fill_geometry(mesh, vertices, triangles)
    reference = calc_edges_mesh(ts, vertices, triangles)
    assert len(mesh.edges) == len(reference.edges) > 0
    np.testing.assert_array_equal(np.unique(edge_pairs(mesh), axis=0), np.unique(edge_pairs(reference), axis=0))
    # each loop's edge joins its vertex and the next loop's vertex of the same triangle
    vertex, edge = loop_arrays(mesh)
    np.testing.assert_array_equal(vertex, triangles.ravel())
    corner_pairs = np.sort(np.stack([triangles, np.roll(triangles, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
    np.testing.assert_array_equal(edge_pairs(mesh)[edge], corner_pairs)
    assert not mesh.validate(verbose=True)  # nothing to fix
    assert len(mesh.edges) == len(reference.edges)
    bm = bmesh.new()
    bm.from_mesh(mesh)
    assert (len(bm.verts), len(bm.edges), len(bm.faces)) == (len(vertices), len(reference.edges), len(triangles))
    assert all(len(f.edges) == 3 for f in bm.faces)
    bm.free()
    bpy.data.meshes.remove(reference)
    return mesh


def test_written_edges_equal_calc_edges_on_closed_and_open_meshes(ts, scene):
    for vertices, triangles in (meshgen.icosphere(3), meshgen.grid(9, 4), meshgen.mobius(), meshgen.book()):
        check_written(ts, np.asarray(vertices, dtype=float), np.asarray(triangles, dtype=np.int32))


def test_decimation_result_edits_after_the_write(ts, scene):
    vertices, triangles = meshgen.torus(48, 24)
    result = ts.core.Mesh(vertices, triangles).decimate(ratio=0.2, seed=4)
    mesh = check_written(ts, result.vertices, result.triangles)
    assert len(result.vertices) - len(mesh.edges) + len(result.triangles) == 0  # still a torus
    obj = bpy.data.objects.new("written", mesh)
    scene.collection.objects.link(obj)
    select_only(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    bm = bmesh.from_edit_mesh(mesh)
    assert len(bm.edges) == len(mesh.edges) and all(e.is_manifold for e in bm.edges)
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.mesh.subdivide()  # an edit that walks the edges
    bpy.ops.object.mode_set(mode="OBJECT")
    assert len(mesh.polygons) == 4 * len(result.triangles)
    assert not mesh.validate(verbose=True)


def test_small_empty_and_degenerate_input(ts, scene):
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    mesh = check_written(ts, vertices, np.array([[0, 1, 2], [1, 3, 2]], dtype=np.int32))
    assert len(mesh.edges) == 5
    empty = bpy.data.meshes.new("empty")
    ts.blender.io.mesh_write.fill_geometry(empty, vertices, np.zeros((0, 3), dtype=np.int32))
    assert (len(empty.vertices), len(empty.edges), len(empty.polygons)) == (4, 0, 0)
    # a repeated vertex has no edge of its own in the engine: Blender derives the edges then
    degenerate = bpy.data.meshes.new("degenerate")
    ts.blender.io.mesh_write.fill_geometry(degenerate, vertices, np.array([[0, 1, 2], [1, 3, 3]], dtype=np.int32))
    assert len(degenerate.polygons) == 2 and len(degenerate.edges) >= 3


def test_edge_flags_writable_after_blenders_edge_pass(ts):
    """Blender 5.0.x's edge pass leaves ``.select_edge`` typed INT32_2D and writing
    ``MeshEdge.select`` then crashes; edge_flags.calc_edges removes such a layer, so the flag
    copy after an edit (mesh_edit) writes and reads back the flags it was given."""
    vertices, triangles = meshgen.icosphere(1)
    mesh = bpy.data.meshes.new("flags")
    m = len(triangles)
    mesh.vertices.add(len(vertices))
    mesh.loops.add(3 * m)
    mesh.polygons.add(m)
    mesh.vertices.foreach_set("co", vertices.astype(np.float32).ravel())
    mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * m, 3, dtype=np.int32))
    if bpy.app.version < (4, 0, 0):
        mesh.polygons.foreach_set("loop_total", np.full(m, 3, dtype=np.int32))
    ts.blender.io.edge_flags.calc_edges(mesh)
    for attribute in mesh.attributes:
        if attribute.name in (".select_edge", ".hide_edge", "sharp_edge"):
            assert (attribute.domain, attribute.data_type) == ("EDGE", "BOOLEAN"), attribute.name
    flags = np.arange(len(mesh.edges)) % 3 == 0
    for name in ("select", "hide", "use_edge_sharp"):
        mesh.edges.foreach_set(name, flags)
        read = np.zeros(len(mesh.edges), dtype=bool)
        mesh.edges.foreach_get(name, read)
        np.testing.assert_array_equal(read, flags)
    assert mesh.validate() is False  # nothing to correct
    bpy.data.meshes.remove(mesh)
