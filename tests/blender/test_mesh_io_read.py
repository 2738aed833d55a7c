"""Reading a Blender mesh into arrays: the shortcuts (a triangle mesh's loop triangles are its
polygons; Blender 4.0+ edge flags from their attributes) give what Blender's own per-element
accessors give."""

import bpy
import numpy as np
import pytest

import meshgen
from helpers import make_object


def reference_triangulation(mesh):
    """Loop triangles read one by one through Blender's API (the independent reference)."""
    mesh.calc_loop_triangles()
    tris = mesh.loop_triangles
    return (np.array([tuple(t.vertices) for t in tris]), np.array([tuple(t.loops) for t in tris]),
            np.array([t.polygon_index for t in tris]))


@pytest.mark.parametrize("kind", ["triangles", "quads and triangles"])
def test_read_mesh_matches_blenders_loop_triangles(ts, scene, kind):
    if kind == "triangles":
        obj = make_object("Ball", *meshgen.icosphere(3))
    else:  # a grid of quads, its last rows split into triangles, and one pentagon
        k = 8
        vertices = [(i, j, 0.1 * ((i * j) % 3)) for i in range(k) for j in range(k)]
        faces = []
        for i in range(k - 1):
            for j in range(k - 1):
                a, b, c, d = i * k + j, (i + 1) * k + j, (i + 1) * k + j + 1, i * k + j + 1
                faces += [(a, b, c, d)] if i < 4 else [(a, b, c), (a, c, d)]
        vertices.append((-1.0, 3.5, 0.0))
        faces.append((0, 1, 2, 3, len(vertices) - 1)[::-1])
        obj = make_object("Grid", vertices, faces)
        assert len(obj.data.loops) != 3 * len(obj.data.polygons)
    arrays = ts.blender.io.mesh_read.read_mesh(obj.data)
    triangles, loops, polygon = reference_triangulation(obj.data)
    np.testing.assert_array_equal(arrays.triangles, triangles)
    np.testing.assert_array_equal(arrays.triangle_loops, loops)
    np.testing.assert_array_equal(arrays.triangle_polygon, polygon)
    assert arrays.triangles.dtype == np.int32 and arrays.triangle_loops.dtype == np.int32
    co = np.array([tuple(v.co) for v in obj.data.vertices])
    np.testing.assert_array_equal(arrays.vertices, co)


@pytest.mark.parametrize("flag", ["use_seam", "use_edge_sharp"])
def test_read_edges_matches_the_per_edge_flags(ts, scene, flag):
    obj = make_object("Ball", *meshgen.icosphere(2))
    mesh = obj.data
    read_edges = ts.blender.io.edge_flags.read_edges
    assert read_edges(mesh, flag).shape == (0, 2)  # none flagged (4.0+: no attribute at all)
    for index in (3, 17, 40):
        setattr(mesh.edges[index], flag, True)
    expected = np.array([tuple(e.vertices) for e in mesh.edges if getattr(e, flag)])
    np.testing.assert_array_equal(read_edges(mesh, flag), expected)
    assert len(expected) == 3


@pytest.mark.parametrize("flag", ["use_seam", "use_edge_sharp"])
def test_read_edges_keeps_each_flag_apart_from_the_others(ts, scene, flag):
    """Every edge flagged some way (the other flag, hidden, selected, creased, bevel weight; Blender
    3.x keeps them side by side in one MEdge): only ``flag`` is read, as MeshEdge gives it."""
    obj = make_object("Ball", *meshgen.icosphere(4))
    mesh = obj.data
    other = "use_edge_sharp" if flag == "use_seam" else "use_seam"
    rng = np.random.default_rng(7)
    for edge in mesh.edges:
        setattr(edge, flag, bool(rng.random() < 0.3))
        setattr(edge, other, bool(rng.random() < 0.5))
        edge.select = bool(rng.random() < 0.5)
        edge.hide = bool(rng.random() < 0.2)
    if hasattr(mesh.edges[0], "crease"):  # Blender < 4.0
        for edge in list(mesh.edges)[::3]:
            edge.crease = 0.75
            edge.bevel_weight = 1.0
    expected = np.array([tuple(e.vertices) for e in mesh.edges if getattr(e, flag)])
    found = ts.blender.io.edge_flags.read_edges(mesh, flag)
    assert found.dtype == np.int32 and len(expected) > 100
    np.testing.assert_array_equal(found, expected)
    if (3, 0, 0) <= bpy.app.version < (4, 0, 0):  # read from the MEdge array, not edge by edge
        np.testing.assert_array_equal(ts.blender.io.dna_arrays.flagged_edges(mesh, flag), expected)


def test_flags_and_loop_order_are_scanned_block_by_block(ts, scene):
    """The scans that make no array of the mesh's size (dna_arrays.SCAN_BLOCK at a time) find
    what lies past the first block: flagged edges there, and a polygon out of loop order there."""
    dna = ts.blender.io.dna_arrays
    starts = np.arange(0, 3 * 200_000, 3, dtype=np.int32)
    assert dna.every_third(starts) and dna.every_third(starts[:0])
    starts[150_000] += 1
    assert not dna.every_third(starts)
    obj = make_object("Ball", *meshgen.icosphere(6))  # 122,880 edges: two blocks
    mesh = obj.data
    assert len(mesh.edges) > dna.SCAN_BLOCK
    for index in (5, dna.SCAN_BLOCK - 1, dna.SCAN_BLOCK, len(mesh.edges) - 1):
        mesh.edges[index].use_seam = True
    expected = np.array([tuple(mesh.edges[i].vertices) for i in (5, dna.SCAN_BLOCK - 1, dna.SCAN_BLOCK,
                                                                  len(mesh.edges) - 1)])
    np.testing.assert_array_equal(ts.blender.io.edge_flags.read_edges(mesh, "use_seam"), expected)
    if (3, 0, 0) <= bpy.app.version < (4, 0, 0):
        np.testing.assert_array_equal(dna.flagged_edges(mesh, "use_seam"), expected)
        assert dna.triangles_in_loop_order(mesh) is True


def test_polygon_materials_and_corners_match_the_per_element_accessors(ts, scene):
    """Loops' vertices, polygons' first loops and material slots as read (Blender 3.x: from the
    MLoop and MPoly arrays in one pass) equal what RNA gives element by element."""
    vertices, faces = meshgen.torus(24, 12)
    faces = [tuple(f) for f in faces]
    quads = [(a, b, c, d) for (a, b, c), (_, _, d) in zip(faces[0:40:2], faces[1:40:2])]  # merged pairs
    obj = make_object("Mixed", vertices, quads + faces[40:])
    mesh = obj.data
    for slot in range(3):
        mesh.materials.append(bpy.data.materials.new(f"Slot{slot}"))
    for polygon in mesh.polygons:
        polygon.material_index = (polygon.index * 7) % 3
    mesh_read, dna = ts.blender.io.mesh_read, ts.blender.io.dna_arrays
    corners = np.array([loop.vertex_index for loop in mesh.loops])
    np.testing.assert_array_equal(mesh_read.corner_vertices(mesh), corners)
    np.testing.assert_array_equal(mesh_read.corner_edges(mesh), [loop.edge_index for loop in mesh.loops])
    arrays = mesh_read.read_mesh(mesh)
    np.testing.assert_array_equal(arrays.polygon_material, [p.material_index for p in mesh.polygons])
    if (3, 0, 0) <= bpy.app.version < (3, 6, 0):  # these Blenders keep MLoop and MPoly arrays
        np.testing.assert_array_equal(dna.loop_indices(mesh, "v"), corners)
        np.testing.assert_array_equal(dna.loop_indices(mesh, "e"), [loop.edge_index for loop in mesh.loops])
        assert dna.triangles_in_loop_order(mesh) is False  # quads among the triangles
        ball = make_object("Ball", *meshgen.icosphere(2)).data
        assert dna.triangles_in_loop_order(ball) is True
    elif bpy.app.version >= (4, 0, 0):
        assert dna.loop_indices(mesh, "v") is None and dna.triangles_in_loop_order(mesh) is None
    assert dna._view(mesh.loops, dna.MEDGE) is None  # a layout of another size is refused


def test_shape_keys_are_read_as_blender_gives_them(ts, scene):
    """A shape key's positions, copied from its float array in one pass, equal what
    ShapeKeyPoint.co gives point by point, for the basis and a key with random offsets."""
    obj = make_object("Morph", *meshgen.icosphere(3))
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Smile", from_mix=False)
    rng = np.random.default_rng(3)
    for point in key.data:
        point.co = tuple(np.array(point.co) + rng.normal(0, 0.1, 3))
    keys = ts.blender.io.carry.read_shape_keys(obj.data)
    assert keys.names == ["Basis", "Smile"]
    for block, read in zip(obj.data.shape_keys.key_blocks, keys.coordinates):
        expected = np.array([tuple(point.co) for point in block.data])
        np.testing.assert_array_equal(read, expected)
        np.testing.assert_array_equal(ts.blender.io.dna_arrays.shape_key_positions(block), expected)


@pytest.mark.parametrize("domain", ["POINT", "CORNER"])
def test_byte_colours_are_read_as_their_stored_srgb_values(ts, scene, domain):
    """A byte colour layer, copied from its bytes in one pass, gives what ByteColorAttributeValue
    .color_srgb gives element by element: every one of the 256 byte values, each channel."""
    obj = make_object("Painted", *meshgen.icosphere(3))
    mesh = obj.data
    layer = mesh.color_attributes.new("Paint", "BYTE_COLOR", domain)
    count = len(mesh.vertices) if domain == "POINT" else len(mesh.loops)
    stored = np.random.default_rng(5).integers(0, 256, (count, 4))
    stored[:64, 0] = np.arange(64) * 4 + 3
    layer.data.foreach_set("color_srgb", (stored / 255.0).astype(np.float32).ravel())
    expected = np.array([tuple(value.color_srgb) for value in layer.data], dtype=np.float32)
    assert len(np.unique(np.round(expected * 255))) == 256
    values, key = ts.blender.io.mesh_attributes.read_attribute(layer, count)
    assert key == "color_srgb"
    np.testing.assert_array_equal(values, expected)
    np.testing.assert_array_equal(ts.blender.io.dna_arrays.byte_colors_srgb(layer), expected)


def test_positions_are_widened_in_place_block_by_block(ts, scene, monkeypatch):
    """The float64 positions, widened inside their own array a block at a time, equal Blender's
    float32 values (read by RNA vertex by vertex) exactly, past block boundaries and at the end;
    a mesh without material slots reads one shared zero for its polygons' slots."""
    mesh_read = ts.blender.io.mesh_read
    monkeypatch.setattr(mesh_read, "WIDEN_BLOCK", 1000)  # 7,680 values: eight blocks, the last partial
    obj = make_object("Ball", *meshgen.icosphere(4))
    mesh = obj.data
    assert 3 * len(mesh.vertices) % 1000 != 0
    arrays = mesh_read.read_mesh(mesh)
    co = np.array([tuple(v.co) for v in mesh.vertices], dtype=np.float32)
    assert arrays.vertices.dtype == np.float64 and arrays.vertices.flags.c_contiguous
    np.testing.assert_array_equal(arrays.vertices, co.astype(np.float64))
    np.testing.assert_array_equal(mesh_read.read_positions(mesh), co)
    assert len(arrays.polygon_material) == len(mesh.polygons) and not np.any(arrays.polygon_material)
    assert arrays.polygon_material.strides == (0,)  # no array a polygon long
    empty = bpy.data.meshes.new("Empty")
    assert mesh_read.read_positions_float64(empty).shape == (0, 3)
