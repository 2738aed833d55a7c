"""What the Guided Decimate operator writes: exact UVs across seams, materials from source faces,
attributes carried over, the original untouched, in-place output, and bad input reported."""

import bpy
import numpy as np
import pytest

import meshgen
from conftest import DATA
from helpers import Params, kept_ids, make_object, positions, select_only, snapshot


def import_obj(path):
    bpy.ops.wm.obj_import(filepath=str(path))
    obj = bpy.context.selected_objects[0]
    select_only(obj)
    return obj


def uv_islands(mesh, uv_name):
    """Independent island labels per polygon: polygons joined across edges whose UVs agree."""
    uv = mesh.uv_layers[uv_name].data
    parent = list(range(len(mesh.polygons)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    half_edges = {}
    for poly in mesh.polygons:
        loops = list(poly.loop_indices)
        for k, loop in enumerate(loops):
            nxt = loops[(k + 1) % len(loops)]
            a, b = mesh.loops[loop].vertex_index, mesh.loops[nxt].vertex_index
            key = (min(a, b), max(a, b))
            uvs = {a: tuple(uv[loop].uv), b: tuple(uv[nxt].uv)}
            half_edges.setdefault(key, []).append((poly.index, uvs))
    for items in half_edges.values():
        for (p, uvs), (q, uvs2) in zip(items, items[1:]):
            if uvs == uvs2:
                parent[find(p)] = find(q)
    return [find(i) for i in range(len(mesh.polygons))]


def island_vertex_uvs(mesh, uv_name, islands):
    """{(island, vertex): set of UVs} of the input."""
    uv = mesh.uv_layers[uv_name].data
    table = {}
    for poly in mesh.polygons:
        for loop in poly.loop_indices:
            key = (islands[poly.index], mesh.loops[loop].vertex_index)
            table.setdefault(key, set()).add(tuple(uv[loop].uv))
    return table


@pytest.mark.parametrize("path", ["uv_materials/duck/duck_via_assimp.obj", "uv_materials/spider/spider.obj"])
def test_uvs_and_materials_survive_exactly(ts, scene, path):
    obj = import_obj(DATA / path)
    source = obj.data
    before = snapshot(source)
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.2, seed=3))
    out = ts.blender.decimation.pipeline.write_output(run)
    assert snapshot(source) == before                        # the original is untouched
    mesh = out.data
    assert len(mesh.polygons) == run.result.num_triangles < len(source.loop_triangles)
    uv_name = source.uv_layers.active.name
    islands = uv_islands(source, uv_name)
    table = island_vertex_uvs(source, uv_name, islands)
    kept = run.result.kept
    arrays = run.prepared.arrays
    source_polygon = arrays.triangle_polygon[run.result.face_source]
    out_uv = mesh.uv_layers[uv_name].data
    materials = [p.material_index for p in source.polygons]
    checked = 0
    for poly in mesh.polygons:
        src = int(source_polygon[poly.index])
        assert poly.material_index == materials[src]          # material from the source face
        for loop in poly.loop_indices:
            vertex = int(kept[mesh.loops[loop].vertex_index])
            uvs = table.get((islands[src], vertex))
            assert uvs is not None, "output corner uses a vertex outside its source face's island"
            assert tuple(out_uv[loop].uv) in uvs               # exactly an input UV of that island
            checked += 1
    assert checked == 3 * len(mesh.polygons)
    assert [m.name for m in mesh.materials] == [m.name for m in source.materials]


@pytest.mark.parametrize("shading", ["flat", "smooth", "mixed"])
def test_shading_and_materials_come_from_the_source_face(ts, scene, shading):
    """Each output face takes its source face's smooth flag and material, whatever Blender's
    default for new faces (flat before 4.0, smooth after). Set and read back per face through
    MeshPolygon, the path the add-on's bulk writes avoid."""
    vertices, faces = meshgen.icosphere(3)
    obj = make_object("Shaded", vertices, faces)
    for slot in range(3):
        obj.data.materials.append(bpy.data.materials.new(f"Slot{slot}"))
    source = obj.data
    for poly in source.polygons:
        poly.use_smooth = {"flat": False, "smooth": True, "mixed": poly.index % 3 == 0}[shading]
        poly.material_index = poly.index % 3
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.3))
    mesh = ts.blender.decimation.pipeline.write_output(run).data
    assert 0 < len(mesh.polygons) < len(source.polygons)
    source_polygon = run.prepared.arrays.triangle_polygon[run.result.face_source]
    assert [p.use_smooth for p in mesh.polygons] == [source.polygons[int(s)].use_smooth for s in source_polygon]
    assert [p.material_index for p in mesh.polygons] == [int(s) % 3 for s in source_polygon]


def test_attributes_and_vertex_groups_carry_over(ts, scene):
    vertices, faces = meshgen.torus(24, 12)
    obj = make_object("Torus", vertices, faces)
    mesh = obj.data
    n = len(mesh.vertices)
    heat = mesh.attributes.new("heat", "FLOAT", "POINT")
    heat.data.foreach_set("value", np.arange(n, dtype=np.float32))
    corner = mesh.attributes.new("corner_id", "INT", "CORNER")
    corner.data.foreach_set("value", np.arange(len(mesh.loops), dtype=np.int32))
    face = mesh.attributes.new("face_id", "INT", "FACE")
    face.data.foreach_set("value", np.arange(len(mesh.polygons), dtype=np.int32))
    colour = mesh.color_attributes.new("Col", "BYTE_COLOR", "CORNER")
    rng = np.random.default_rng(1)
    colour.data.foreach_set("color", rng.random(4 * len(mesh.loops)).astype(np.float32))
    group = obj.vertex_groups.new(name="Ring")
    group.add(list(range(0, n, 2)), 0.25, "REPLACE")
    group.add(list(range(1, n, 2)), 0.75, "REPLACE")
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.3))
    out = ts.blender.decimation.pipeline.write_output(run)
    m = out.data
    kept = kept_ids(mesh, m)
    np.testing.assert_array_equal(kept, run.result.kept)
    values = np.empty(len(m.vertices), dtype=np.float32)
    m.attributes["heat"].data.foreach_get("value", values)
    np.testing.assert_array_equal(values, kept)
    ids = np.empty(len(m.loops), dtype=np.int32)
    m.attributes["corner_id"].data.foreach_get("value", ids)
    loop_vertex = np.array([l.vertex_index for l in mesh.loops])
    out_loop_vertex = np.array([l.vertex_index for l in m.loops])
    np.testing.assert_array_equal(loop_vertex[ids], kept[out_loop_vertex])   # a corner of the same vertex
    face_ids = np.empty(len(m.polygons), dtype=np.int32)
    m.attributes["face_id"].data.foreach_get("value", face_ids)
    np.testing.assert_array_equal(face_ids, run.prepared.arrays.triangle_polygon[run.result.face_source])
    src_colour = np.empty(4 * len(mesh.loops), dtype=np.float32)
    mesh.color_attributes["Col"].data.foreach_get("color", src_colour)
    out_colour = np.empty(4 * len(m.loops), dtype=np.float32)
    m.color_attributes["Col"].data.foreach_get("color", out_colour)
    np.testing.assert_array_equal(out_colour.reshape(-1, 4), src_colour.reshape(-1, 4)[ids])
    weights = {v.index: v.groups[0].weight for v in m.vertices if len(v.groups)}
    assert len(weights) == len(m.vertices)
    for i, w in weights.items():
        assert w == pytest.approx(0.25 if kept[i] % 2 == 0 else 0.75)


def test_custom_normals_carry_over(ts, scene):
    vertices, faces = meshgen.icosphere(2)
    obj = make_object("Ball", vertices, faces)
    mesh = obj.data
    normals = np.tile([0.0, 0.0, 1.0], (len(mesh.loops), 1))
    if hasattr(mesh, "use_auto_smooth"):
        mesh.use_auto_smooth = True
    mesh.normals_split_custom_set(normals.tolist())
    assert mesh.has_custom_normals
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.3))
    out = ts.blender.decimation.pipeline.write_output(run).data
    assert out.has_custom_normals
    if hasattr(out, "corner_normals"):
        values = np.array([n.vector[:] for n in out.corner_normals])
    else:
        out.calc_normals_split()
        values = np.array([l.normal[:] for l in out.loops])
    np.testing.assert_allclose(values, np.tile([0, 0, 1.0], (len(out.loops), 1)), atol=1e-2)  # Blender stores them compressed


def test_operator_new_object_keeps_original(ts, scene):
    vertices, faces = meshgen.torus(32, 16)
    obj = make_object("Donut", vertices, faces)
    before = snapshot(obj.data)
    assert bpy.ops.topstoc.guided_decimate(ratio=0.25, seed=1) == {"FINISHED"}
    assert snapshot(obj.data) == before
    out = bpy.data.objects["Donut_TopStoc"]
    assert bpy.context.view_layer.objects.active == out
    assert 0 < len(out.data.vertices) < len(obj.data.vertices)
    xs = [c[0] for c in obj.bound_box]  # beside the original, offset by its width along X
    assert tuple(out.matrix_world.translation) == pytest.approx((1.1 * (max(xs) - min(xs)), 0.0, 0.0))
    assert not obj.hide_get()
    assert out["topstoc_source"] == "Donut"


def test_operator_targets(ts, scene):
    vertices, faces = meshgen.icosphere(4)
    obj = make_object("Ball", vertices, faces)
    bpy.ops.topstoc.guided_decimate(target_mode="VERTICES", vertices=500)
    assert abs(len(bpy.data.objects["Ball_TopStoc"].data.vertices) - 500) <= 5
    select_only(obj)
    bpy.ops.topstoc.guided_decimate(target_mode="TRIANGLES", triangles=600)
    out = bpy.data.objects["Ball_TopStoc.001"]
    assert abs(len(out.data.polygons) - 600) <= 12


def test_operator_in_place(ts, scene):
    vertices, faces = meshgen.torus(32, 16)
    obj = make_object("Donut", vertices, faces)
    name = obj.data.name
    assert bpy.ops.topstoc.guided_decimate(ratio=0.25, output="IN_PLACE") == {"FINISHED"}
    assert [o.name for o in bpy.data.objects] == ["Donut"]
    assert obj.data.name == name
    assert len(obj.data.vertices) == round(0.25 * len(vertices)) or len(obj.data.vertices) < len(vertices)


def test_all_selected_meshes_are_decimated(ts, scene):
    a = make_object("A", *meshgen.icosphere(3))
    b = make_object("B", *meshgen.torus(24, 12))
    a.select_set(True)
    assert bpy.ops.topstoc.guided_decimate(ratio=0.2) == {"FINISHED"}
    assert {"A_TopStoc", "B_TopStoc"} <= set(bpy.data.objects.keys())


def _reports_error(ts, obj, match, **params):
    with pytest.raises(ts.blender.decimation.pipeline.DecimationError, match=match):
        ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(**params))


def test_bad_input_is_reported_and_nothing_is_lost(ts, scene):
    empty = make_object("Points", [(0, 0, 0), (1, 0, 0)], [])
    _reports_error(ts, empty, "has no faces")
    with pytest.raises(RuntimeError, match="has no faces"):
        bpy.ops.topstoc.guided_decimate(ratio=0.5)
    assert len(empty.data.vertices) == 2
    ball = make_object("Ball", *meshgen.icosphere(2))
    _reports_error(ts, ball, "vertex target .* outside", target_mode="VERTICES", vertices=10 ** 9)
    _reports_error(ts, ball, "triangle target .* outside", target_mode="TRIANGLES", triangles=10 ** 9)
    assert len(ball.data.vertices) == 162 and len(bpy.data.objects) == 2


def test_messy_meshes_decimate(ts, scene):
    """Loose vertices and edges, a zero-area face, a non-manifold fin: decimated, originals kept."""
    vertices, faces = meshgen.icosphere(3)
    vertices = np.vstack([vertices, [[3, 0, 0], [4, 0, 0], [5, 0, 0], [0, 0, 2], [0, 0, 2.5]]])
    n = len(vertices)
    faces = [tuple(f) for f in faces] + [(n - 5, n - 4, n - 3)]          # zero-area (collinear)
    a, b = faces[0][0], faces[0][1]
    faces += [(a, b, n - 2)]                                              # a fin: non-manifold edge a-b
    mesh = bpy.data.meshes.new("Messy")
    mesh.from_pydata(vertices.tolist(), [(n - 2, n - 1)], faces)          # loose edge + loose vertex
    obj = bpy.data.objects.new("Messy", mesh)
    scene.collection.objects.link(obj)
    select_only(obj)
    before = snapshot(mesh)
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.2))
    report = run.prepared.mesh.report()
    assert report.nonmanifold_edges >= 1 and report.zero_area_triangles >= 1 and report.isolated_vertices >= 1
    out = ts.blender.decimation.pipeline.write_output(run)
    assert 0 < len(out.data.polygons) < len(faces)
    assert snapshot(mesh) == before


def test_cache_reprepares_after_an_edit(ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(3))
    cache = ts.blender.preview.cache.prepared_meshes
    first = cache.get(obj.data)
    assert cache.get(obj.data) is first                   # unchanged: reused
    co = positions(obj.data)
    co[0] *= 1.5
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    second = cache.get(obj.data)
    assert second is not first                            # edited: prepared again
    np.testing.assert_allclose(second.mesh.vertices[0], co[0])


def test_cache_clear_kept_frees_the_collapse_states_and_keeps_the_preparation(ts, scene):
    obj = make_object("Torus", *meshgen.bumpy_torus(20000))  # collapsed whole: its quality runs keep states
    cache = ts.blender.preview.cache.prepared_meshes
    prepared = cache.get(obj.data)
    first = prepared.mesh.decimate(ratio=0.05)
    assert prepared.mesh.kept_for_reuse()[2].size >= 1
    cache.clear_kept()
    assert prepared.mesh.kept_for_reuse()[2].size == 0
    assert cache.get(obj.data) is prepared                # still cached: not prepared again
    np.testing.assert_array_equal(prepared.mesh.decimate(ratio=0.05).triangles, first.triangles)


def test_max_deviation_target(ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(4))
    params = Params(target_mode="MAX_ERROR", max_error=1.0, max_error_relative=True)
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, params)
    assert run.parameters["max_error"] == pytest.approx(0.01) and run.parameters["relative"]
    assert run.result.num_vertices < len(obj.data.vertices)
    # Measured independently of the search: the symmetric Hausdorff error is within 1 % of the diagonal.
    import importlib

    hausdorff = importlib.import_module(ts.__name__ + ".core.api.hausdorff")
    mesh = run.prepared.mesh
    measured = hausdorff.hausdorff((mesh.vertices, mesh.triangles), (run.result.vertices, run.result.triangles),
                                   samples=200_000)
    assert measured.symmetric.max <= 0.01 * mesh.diagonal * 1.05
    out = ts.blender.decimation.pipeline.write_output(run)
    assert len(out.data.vertices) == run.result.num_vertices
