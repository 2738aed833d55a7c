"""Vertices the quality mode moves take interpolated attributes in the add-on's output: UVs (per
corner, seams exact), colour and float attributes, integers from the nearest corner, and each
shape key's offset interpolated at the vertex's place on the basis.

The reference is independent of the add-on's code: a "rest" attribute holding each vertex's own
position comes out, at a moved vertex, as the point of the input surface its values were taken
from. The test finds the input triangles through that point by brute force, solves for its
barycentric coordinates there, and checks every other value against them."""

import bpy
import numpy as np
import pytest

import meshgen
from helpers import Params, make_object, positions


def point_triangle_distance(p, a, b, c):
    """Distance from point p to each triangle (a, b, c) (rows), by the textbook case split:
    inside the prism its plane distance, else the nearest of the three edges."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    inside = np.ones(len(a), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, p - u), n) >= 0
    plane = np.abs(np.einsum("ij,ij->i", p - a, n))

    def segment(u, v):
        t = np.clip(np.einsum("ij,ij->i", p - u, v - u) / np.einsum("ij,ij->i", v - u, v - u), 0, 1)
        return np.linalg.norm(p - (u + t[:, None] * (v - u)), axis=1)

    edge = np.minimum(np.minimum(segment(a, b), segment(b, c)), segment(c, a))
    return np.where(inside, plane, edge)


def barycentric(p, a, b, c):
    """Coordinates of p in triangle (a, b, c) by least squares on the two edge vectors."""
    matrix = np.stack([b - a, c - a], axis=1)
    (s, t), *_ = np.linalg.lstsq(matrix, p - a, rcond=None)
    return np.array([1 - s - t, s, t])


def sphere_with_everything():
    vertices, triangles = meshgen.icosphere(4)
    obj = make_object("Ball", vertices, triangles)
    mesh = obj.data
    n = len(vertices)
    rng = np.random.default_rng(7)
    rest = mesh.attributes.new("rest", "FLOAT_VECTOR", "POINT")
    rest.data.foreach_set("vector", vertices.astype(np.float32).ravel())
    height = mesh.attributes.new("height", "FLOAT", "POINT")
    height.data.foreach_set("value", vertices[:, 2].astype(np.float32))
    paint = mesh.attributes.new("paint", "FLOAT_COLOR", "POINT")
    rgba = np.c_[0.5 + 0.4 * vertices, np.ones(n)]
    paint.data.foreach_set("color", rgba.astype(np.float32).ravel())
    ids = mesh.attributes.new("id", "INT", "POINT")
    ids.data.foreach_set("value", np.arange(n, dtype=np.int32))
    # a corner colour, one random colour per vertex
    speckle = mesh.attributes.new("speckle", "BYTE_COLOR", "CORNER")
    per_vertex = np.c_[rng.random((n, 3)), np.ones(n)]
    corner_vertex = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", corner_vertex)
    speckle.data.foreach_set("color", per_vertex[corner_vertex].astype(np.float32).ravel())
    mesh.color_attributes.active_color = mesh.color_attributes["paint"]  # the look's colour
    # a spherical UV map, cut open along one meridian (a real seam: two UVs at its vertices)
    uv = mesh.uv_layers.new(name="UVMap")
    co = vertices[corner_vertex]
    u = np.arctan2(co[:, 1], co[:, 0]) / (2 * np.pi) + 0.5
    loops = u.reshape(-1, 3)
    wrap = (loops.max(axis=1) - loops.min(axis=1)) > 0.5
    loops[wrap] = np.where(loops[wrap] < 0.5, loops[wrap] + 1.0, loops[wrap])
    uv.data.foreach_set("uv", np.c_[loops.ravel(), 0.5 + 0.5 * co[:, 2]].astype(np.float32).ravel())
    # shape keys: a smooth bulge and a random field
    obj.shape_key_add(name="Basis", from_mix=False)
    bulge = obj.shape_key_add(name="Bulge", from_mix=False)
    bulge.data.foreach_set("co", (vertices * (1 + 0.2 * vertices[:, 2:3] ** 2)).astype(np.float32).ravel())
    noise = obj.shape_key_add(name="Noise", from_mix=False)
    noise.data.foreach_set("co", (vertices + 0.05 * rng.standard_normal((n, 3))).astype(np.float32).ravel())
    return obj


def attribute(mesh, name, key, width):
    values = np.empty(len(mesh.attributes[name].data) * width, dtype=np.float64)
    mesh.attributes[name].data.foreach_get(key, values)
    return values.reshape(-1, width)


def key_positions(mesh, name):
    co = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    mesh.shape_keys.key_blocks[name].data.foreach_get("co", co)
    return co.reshape(-1, 3)


def corner_data(mesh):
    corner_vertex = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", corner_vertex)
    uv = np.empty(2 * len(mesh.loops), dtype=np.float64)
    mesh.uv_layers["UVMap"].data.foreach_get("uv", uv)
    return corner_vertex, uv.reshape(-1, 2)


@pytest.fixture
def quality_result(ts, scene):
    """The look out of the cost (attribute weight 0): every layer is carried, none fitted."""
    obj = sphere_with_everything()
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.1, quality="QUALITY", seed=3,
                                                                        attribute_weight=0.0))
    out = ts.blender.decimation.pipeline.write_output(run)
    return obj, out


@pytest.fixture
def look_result(ts, scene, monkeypatch):
    """The look in the cost (the default): the source, the result written as the add-on writes
    it (the look's layers fitted) and the same result with every layer carried."""
    obj = sphere_with_everything()
    pipeline = ts.blender.decimation.pipeline
    run = pipeline.decimate(bpy.context, obj, Params(ratio=0.1, quality="QUALITY", seed=3))
    assert pipeline.look_layers(run) == {"uv": "UVMap", "color": "paint", "normal": False}
    fitted = pipeline.write_output(run)
    monkeypatch.setattr(pipeline, "look_layers", lambda run: None)
    return obj, fitted, pipeline.write_output(run)


def test_moved_vertices_interpolate_in_their_source_triangle(quality_result):
    source, out = quality_result
    src, dst = source.data, out.data
    v_in = positions(src).astype(np.float64)
    v_out = positions(dst).astype(np.float64)
    tris = np.array([tuple(p.vertices) for p in src.polygons])
    index = {tuple(p): i for i, p in enumerate(positions(src).tolist())}
    kept = np.array([index.get(tuple(p), -1) for p in positions(dst).tolist()])
    moved = np.flatnonzero(kept < 0)
    assert len(moved) >= 50, len(moved)  # the quality mode moves most free vertices

    rest = attribute(dst, "rest", "vector", 3)
    height = attribute(dst, "height", "value", 1)[:, 0]
    paint = attribute(dst, "paint", "color", 4)
    ids = attribute(dst, "id", "value", 1)[:, 0]
    speckle_in = attribute(src, "speckle", "color", 4)
    speckle_out = attribute(dst, "speckle", "color", 4)
    corner_in, uv_in = corner_data(src)
    corner_out, uv_out = corner_data(dst)
    keys_in = {name: key_positions(src, name) for name in ("Bulge", "Noise")}
    keys_out = {name: key_positions(dst, name) for name in ("Bulge", "Noise")}

    # vertices that did not move carry their input vertex's values exactly
    still = np.flatnonzero(kept >= 0)
    np.testing.assert_array_equal(rest[still], positions(src)[kept[still]])
    np.testing.assert_array_equal(ids[still], kept[still])
    for name in keys_in:
        np.testing.assert_array_equal(keys_out[name][still], keys_in[name][kept[still]].astype(np.float32))

    diagonal = np.linalg.norm(v_in.max(axis=0) - v_in.min(axis=0))
    a, b, c = v_in[tris[:, 0]], v_in[tris[:, 1]], v_in[tris[:, 2]]
    edge = np.linalg.norm(b - a, axis=1).mean()
    for v in moved:
        point = rest[v]
        distance = point_triangle_distance(np.broadcast_to(point, a.shape), a, b, c)
        on = np.flatnonzero(distance <= 1e-5 * diagonal)
        assert len(on), f"vertex {v}: its rest point is {distance.min():.2e} off the input surface"
        # ... taken where the vertex now stands: the input surface's point nearest to it (the
        # kept vertex it was copied from before could be two edges away)
        nearest = point_triangle_distance(np.broadcast_to(v_out[v], a.shape), a, b, c).min()
        assert np.linalg.norm(point - v_out[v]) <= nearest + 0.05 * edge, (v, nearest / edge)
        ok_height = ok_paint = ok_id = ok_speckle = ok_uv = ok_keys = False
        corners = np.flatnonzero(corner_out == v)
        assert np.allclose(uv_out[corners], uv_out[corners[0]], atol=1e-6)  # no new seam
        for t in on:  # any triangle through the point (it may sit on an edge) must explain the values
            w = barycentric(point, *v_in[tris[t]])
            ok_height |= abs(height[v] - w @ v_in[tris[t], 2]) <= 1e-5
            ok_paint |= np.allclose(paint[v, :3], 0.5 + 0.4 * (w @ v_in[tris[t]]), atol=1e-5)
            ok_id |= int(ids[v]) in tris[t]
            loops = np.array(src.polygons[t].loop_indices)
            lo, hi = speckle_in[loops].min(axis=0), speckle_in[loops].max(axis=0)
            ok_speckle |= bool(np.all((lo - 1 / 255 <= speckle_out[corners]) & (speckle_out[corners] <= hi + 1 / 255)))
            ok_uv |= np.allclose(uv_out[corners[0]], w @ uv_in[loops], atol=1e-5)
            ok_keys |= all(np.allclose(keys_out[name][v], v_out[v] + w @ (keys_in[name][tris[t]] - v_in[tris[t]]),
                                       atol=1e-5) for name in keys_in)
        assert ok_height and ok_paint and ok_id and ok_speckle and ok_uv and ok_keys, \
            (v, ok_height, ok_paint, ok_id, ok_speckle, ok_uv, ok_keys)


@pytest.mark.parametrize("which", ["carried", "fitted"])
def test_uvs_stay_exact_at_seams(quality_result, look_result, which):
    source, out = quality_result if which == "carried" else look_result[:2]
    src, dst = source.data, out.data
    corner_in, uv_in = corner_data(src)
    corner_out, uv_out = corner_data(dst)
    index = {tuple(p): i for i, p in enumerate(positions(src).tolist())}
    kept = np.array([index.get(tuple(p), -1) for p in positions(dst).tolist()])
    uvs_at = {}
    for loop, vertex in enumerate(corner_in):
        uvs_at.setdefault(vertex, set()).add(tuple(uv_in[loop]))
    seam_vertices = {v for v, uvs in uvs_at.items() if len(uvs) > 1}
    on_seam = 0
    for loop, vertex in enumerate(corner_out):
        source_vertex = kept[vertex]
        if source_vertex in seam_vertices:
            on_seam += 1
            assert tuple(uv_out[loop]) in uvs_at[source_vertex]  # one side's UV exactly, never a mix
    assert on_seam >= 20  # (no seam vertex moved: a moved vertex has one UV, see the test above)


def _mapping_error(mesh) -> dict:
    """Area-weighted mean error at the triangles' quadrature points of the UV map's v and of the
    paint's red against the closed forms sphere_with_everything painted them with (v = 0.5 +
    0.5 z, red = 0.5 + 0.4 x, at the point's direction on the unit sphere)."""
    corner_vertex, uv = corner_data(mesh)
    red = attribute(mesh, "paint", "color", 4)[:, 0]
    v = positions(mesh).astype(np.float64)
    loops = np.array([tuple(p.loop_indices) for p in mesh.polygons])
    corners = v[corner_vertex[loops]]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    errors = {"v": 0.0, "red": 0.0}
    for w in np.full((3, 3), 1 / 6) + np.eye(3) / 2:
        point = np.einsum("j,mjk->mk", w, corners)
        unit = point / np.linalg.norm(point, axis=1, keepdims=True)
        errors["v"] += (area * np.abs(uv[loops, 1] @ w - (0.5 + 0.5 * unit[:, 2]))).sum()
        errors["red"] += (area * np.abs(red[corner_vertex[loops]] @ w - (0.5 + 0.4 * unit[:, 0]))).sum()
    return {name: value / (3 * area.sum()) for name, value in errors.items()}


def test_the_look_is_fitted_to_the_source(look_result):
    """The active UV map and the appearance colour were in the cost: written fitted
    (core/carry/look_fit), they follow the closed-form mapping and paint closer than carried
    from the kept vertices; layers outside the look are carried the same either way."""
    source, fitted, carried = look_result
    errors = {name: _mapping_error(out.data) for name, out in (("fitted", fitted), ("carried", carried))}
    assert errors["fitted"]["v"] < 0.5 * errors["carried"]["v"], errors
    assert errors["fitted"]["red"] < 0.5 * errors["carried"]["red"], errors
    for name, key, width in (("height", "value", 1), ("speckle", "color", 4), ("id", "value", 1)):
        np.testing.assert_array_equal(attribute(fitted.data, name, key, width), attribute(carried.data, name, key, width))
