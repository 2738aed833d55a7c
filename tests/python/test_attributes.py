"""UV seams and attribute transfer (topstoc.core.carry.attributes) against brute force."""

import pathlib

import numpy as np

from meshgen import torus
from topstoc.core import Mesh
from topstoc.core.carry.attributes import material_regions, transfer_attributes, uv_seam_edges
from topstoc.core.api.io import MeshData, read_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


def brute_force_seams(triangles, corner_uvs):
    sides = {}
    for t, tri in enumerate(triangles):
        if len(set(tri.tolist())) < 3:
            continue
        for c in range(3):
            a, b = int(tri[c]), int(tri[(c + 1) % 3])
            ua, ub = tuple(corner_uvs[t, c]), tuple(corner_uvs[t, (c + 1) % 3])
            key, value = ((a, b), (ua, ub)) if a < b else ((b, a), (ub, ua))
            sides.setdefault(key, set()).add(value)
    return {key for key, values in sides.items() if len(values) > 1}


def test_seams_of_the_test_files_match_brute_force():
    for name in ("uv_materials/spider/spider.obj", "uv_materials/duck/duck_via_assimp.obj"):
        data = read_mesh(DATA / name)
        seams = uv_seam_edges(data.triangles, data.corner_uvs)
        assert seams.dtype == np.int32 and (seams[:, 0] < seams[:, 1]).all()
        assert {tuple(e) for e in seams.tolist()} == brute_force_seams(data.triangles, data.corner_uvs), name


def test_torus_cut_open_by_its_uvs_has_exactly_those_seams():
    nu, nv = 12, 6
    vertices, triangles = torus(nu, nv)
    # meshgen's grid: face pair f // 2 = i * nv + j, triangles (i,j)(i+1,j)(i+1,j+1) and
    # (i,j)(i+1,j+1)(i,j+1). UVs from the unwrapped grid cut the torus along i = 0 and j = 0.
    f = np.arange(len(triangles))
    i, j = (f // 2) // nv, (f // 2) % nv
    offsets = np.where((f % 2 == 0)[:, None, None], [[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]])
    grid = np.stack([i, j], axis=-1)[:, None, :] + offsets
    uvs = grid / [nu, nv]
    seams = {tuple(e) for e in uv_seam_edges(triangles, uvs).tolist()}
    assert seams == brute_force_seams(triangles, uvs)
    assert len(seams) == nu + nv  # one meridian and one parallel loop


def test_no_uv_differences_no_seams():
    vertices, triangles = torus(8, 4)
    uvs = vertices[triangles][..., :2]  # a function of the vertex: continuous everywhere
    assert len(uv_seam_edges(triangles, uvs)) == 0
    nan = np.full((len(triangles), 3, 2), np.nan)
    assert len(uv_seam_edges(triangles, nan)) == 0


def test_transfer_copies_through_the_source_maps():
    data = read_mesh(DATA / "uv_materials" / "spider" / "spider.obj")
    mesh = Mesh(data.vertices, data.triangles)
    result = mesh.decimate(ratio=0.5, regions=material_regions(data),
                           borders=uv_seam_edges(data.triangles, data.corner_uvs), mode="fast")
    out = transfer_attributes(data, result)
    np.testing.assert_array_equal(out.triangle_material, data.triangle_material[result.face_source])
    flat = data.corner_uvs.reshape(-1, 2)
    np.testing.assert_array_equal(out.corner_uvs, flat[result.corner_source.ravel()].reshape(-1, 3, 2))
    # The source corner belongs to the kept vertex.
    np.testing.assert_array_equal(data.triangles.ravel()[result.corner_source.ravel()],
                                  result.kept[result.triangles.ravel()])
    assert out.material_names == data.material_names


def test_every_output_corner_has_a_source_corner_of_its_vertex():
    # A fast decimation with UV seams walks each output corner's cluster back to its sample for
    # a corner on the same side of the seams; where the flood's steps led nowhere (a repaired
    # cluster) the corner was -1, and the caller's arrays were read from their end (the duck at
    # 20 %, seed 2: 4 corners).
    data = read_mesh(DATA / "uv_materials" / "duck" / "duck_via_assimp.obj")
    mesh = Mesh(data.vertices, data.triangles)
    borders = uv_seam_edges(data.triangles, data.corner_uvs)
    for ratio in (0.5, 0.3, 0.2, 0.1):
        for seed in range(5):
            result = mesh.decimate(ratio=ratio, seed=seed, borders=borders, mode="fast")
            corners = np.asarray(result.corner_source).ravel()
            assert corners.min() >= 0, (ratio, seed)
            np.testing.assert_array_equal(data.triangles.ravel()[corners], result.kept[result.triangles.ravel()])


def test_single_material_is_no_region():
    assert material_regions(MeshData(vertices=np.zeros((3, 3)), triangles=[[0, 1, 2]],
                                     triangle_material=[0], material_names=["a"])) is None


def test_quality_mode_interpolates_moved_vertices_and_keeps_seams_exact():
    data = read_mesh(DATA / "uv_materials" / "spider" / "spider.obj")
    mesh = Mesh(data.vertices, data.triangles)
    seams = uv_seam_edges(data.triangles, data.corner_uvs)
    for ratio in (0.3, 0.1):
        result = mesh.decimate(ratio=ratio, regions=material_regions(data), borders=seams)  # quality
        out = transfer_attributes(data, result)
        moved = np.any(result.vertices != data.vertices[result.kept], axis=1)
        assert moved.sum() >= 10  # the spider is mostly seams: few vertices are free to move
        # vertices on a seam or material border never move, and keep their corners' UVs exactly
        on_seam = np.zeros(len(data.vertices), bool)
        on_seam[seams.ravel()] = True
        assert not moved[on_seam[result.kept]].any()
        flat = data.corner_uvs.reshape(-1, 2)
        exact = ~moved[result.triangles.ravel()]
        np.testing.assert_array_equal(out.corner_uvs.reshape(-1, 2)[exact], flat[result.corner_source.ravel()][exact])
        # a moved vertex's UV lies within the range of one input triangle's corner UVs, the
        # triangle being one of its cluster (checked by brute force over those triangles)
        for v in np.flatnonzero(moved)[:200]:
            uv = out.corner_uvs.reshape(-1, 2)[np.flatnonzero(result.triangles.ravel() == v)]
            assert np.allclose(uv, uv[0])  # one value per interior vertex
            cluster = np.flatnonzero(result.labels == v)
            candidates = np.flatnonzero(np.isin(data.triangles, cluster).any(axis=1))
            lo, hi = data.corner_uvs[candidates].min(axis=1), data.corner_uvs[candidates].max(axis=1)
            assert np.any(np.all((lo - 1e-12 <= uv[0]) & (uv[0] <= hi + 1e-12), axis=1)), v


def test_quality_mode_colours_within_the_source_triangle():
    vertices, triangles = torus(40, 20)
    colors = np.random.default_rng(1).random((len(vertices), 3))
    data = MeshData(vertices=vertices, triangles=triangles, vertex_colors=colors)
    result = Mesh(vertices, triangles).decimate(ratio=0.25, seed=2)
    out = transfer_attributes(data, result)
    moved = np.any(result.vertices != vertices[result.kept], axis=1)
    assert moved.any()
    np.testing.assert_array_equal(out.vertex_colors[~moved], colors[result.kept[~moved]])
    for v in np.flatnonzero(moved):
        cluster = np.flatnonzero(result.labels == v)
        candidates = np.flatnonzero(np.isin(triangles, cluster).any(axis=1))
        lo, hi = colors[triangles[candidates]].min(axis=1), colors[triangles[candidates]].max(axis=1)
        assert np.any(np.all((lo - 1e-12 <= out.vertex_colors[v]) & (out.vertex_colors[v] <= hi + 1e-12), axis=1))


def test_point_and_corner_values_by_hand():
    """Two input triangles sharing edge (1, 2), with a seam there (corner values differ across
    it); output vertex 0 stays at input vertex 0, output vertex 1 moved into triangle 1."""
    from topstoc.core.carry.attributes import MovedVertices, corner_values, point_values

    triangles = np.array([[0, 1, 2], [2, 1, 3]])
    moved = MovedVertices(face=np.array([-1, 1]), weights=np.array([[1.0, 0, 0], [0.2, 0.3, 0.5]]))
    kept = np.array([0, 3])
    values = np.array([[0.0], [10.0], [20.0], [30.0]], dtype=np.float32)
    out = point_values(values, kept, moved, triangles)
    assert out.dtype == np.float32
    np.testing.assert_allclose(out[:, 0], [0.0, 0.2 * 20 + 0.3 * 10 + 0.5 * 30])
    ids = np.arange(4, dtype=np.int32)[:, None]
    np.testing.assert_array_equal(point_values(ids, kept, moved, triangles, nearest=True)[:, 0], [0, 3])
    # corners: 6 input corners (triangle-major); the output triangle (0, 1, 1)'s corners copy corners 0, 4, 4
    corner = np.array([[1.0], [2.0], [3.0], [-3.0], [-2.0], [-1.0]])  # triangle 1's side of the seam is negative
    flat = corner_values(corner, np.array([0, 4, 4]), np.array([[0, 1, 1]]), moved, np.arange(6).reshape(2, 3))
    np.testing.assert_allclose(flat[:, 0], [1.0, 0.2 * -3 + 0.3 * -2 + 0.5 * -1, 0.2 * -3 + 0.3 * -2 + 0.5 * -1])


def dense_weights(weights, rows, columns):
    """(rows, columns) weights and membership of a SparseWeights, one row per vertex."""
    table = np.zeros((rows, columns))
    member = np.zeros((rows, columns), dtype=bool)
    for v, g, w in zip(weights.vertex.tolist(), weights.group.tolist(), weights.weight.tolist()):
        assert not member[v, g], (v, g)  # one entry per (vertex, group)
        table[v, g], member[v, g] = w, True
    return table, member


def test_point_weights_by_hand():
    """Vertex 0 did not move (its zero weight in group 2 stays); vertex 1 moved into triangle 1,
    whose corners 2, 1, 3 have weights in groups 0, 1 and 2 (corner 3 only in group 2)."""
    from topstoc.core.carry.attributes import MovedVertices, SparseWeights, point_weights

    triangles = np.array([[0, 1, 2], [2, 1, 3]])
    moved = MovedVertices(face=np.array([-1, 1]), weights=np.array([[1.0, 0, 0], [0.2, 0.3, 0.5]]))
    source = SparseWeights(vertex=np.array([0, 0, 1, 2, 2, 3]), group=np.array([0, 2, 1, 0, 1, 2]),
                           weight=np.array([1.0, 0.0, 1.0, 0.25, 0.75, 1.0]))
    out = point_weights(source, np.array([0, 3]), moved, triangles)
    table, member = dense_weights(out, 2, 3)
    np.testing.assert_array_equal(member[0], [True, False, True])        # kept exactly, the 0 too
    np.testing.assert_array_equal(table[0], [1.0, 0.0, 0.0])
    np.testing.assert_allclose(table[1], [0.2 * 0.25, 0.2 * 0.75 + 0.3 * 1.0, 0.5 * 1.0])  # group 0 via corner 2 only
    assert member[1].all() and abs(table[1].sum() - 1.0) < 1e-12       # normalised corners, normalised mix
    # a corner with barycentric weight 0 gives nothing: no group with a zero mix
    flat = MovedVertices(face=np.array([-1, 1]), weights=np.array([[1.0, 0, 0], [0.0, 1.0, 0.0]]))
    table, member = dense_weights(point_weights(source, np.array([0, 3]), flat, triangles), 2, 3)
    np.testing.assert_array_equal(member[1], [False, True, False])
    # normalise: a corner without weights (vertex 4) would leave the mix short of 1
    source4 = SparseWeights(vertex=np.array([1, 2]), group=np.array([0, 0]), weight=np.array([1.0, 1.0]))
    tri = MovedVertices(face=np.array([0]), weights=np.array([[0.5, 0.25, 0.25]]))
    short = point_weights(source4, np.array([4]), tri, np.array([[4, 1, 2]]))
    np.testing.assert_allclose(short.weight, [0.5])
    assert source4.normalised() and not short.normalised()
    full = point_weights(source4, np.array([4]), tri, np.array([[4, 1, 2]]), normalise=True)
    np.testing.assert_allclose(full.weight, [1.0])


def test_point_weights_match_a_dense_mix_on_a_quality_decimation():
    """Random sparse weights on a torus through a quality decimation against the dense
    reference: kept vertices copy their rows, moved ones mix their source triangle's rows."""
    from topstoc.core.carry.attributes import SparseWeights, moved_vertices, point_weights

    vertices, triangles = torus(40, 20)
    rng = np.random.default_rng(5)
    n, groups = len(vertices), 6
    member = rng.random((n, groups)) < 0.4
    table = np.where(member, rng.random((n, groups)), 0.0)
    table[member & (rng.random((n, groups)) < 0.1)] = 0.0              # some explicit zero weights
    rows, columns = np.nonzero(member)
    source = SparseWeights(rows, columns, table[rows, columns])
    result = Mesh(vertices, triangles).decimate(ratio=0.2, seed=4)
    moved = moved_vertices(vertices, triangles, result)
    assert len(moved.moved) > 50
    out_table, out_member = dense_weights(point_weights(source, result.kept, moved, triangles), len(result.kept), groups)
    still = moved.face < 0
    np.testing.assert_array_equal(out_table[still], table[result.kept[still]])
    np.testing.assert_array_equal(out_member[still], member[result.kept[still]])
    at = moved.moved
    corners = triangles[moved.face[at]]
    expected = np.einsum("kj,kjg->kg", moved.weights[at], table[corners])
    np.testing.assert_allclose(out_table[at], expected, atol=1e-12)
    np.testing.assert_array_equal(out_member[at], expected != 0)


def _clamped_barycentric(points, a, b, c):
    """Reference: barycentric weights of each point's projection onto triangle (a, b, c),
    negative weights clamped to 0 and the rest renormalised, and the distance from the point to
    the weighted point; degenerate triangles give their first corner."""
    e0, e1, d = b - a, c - a, points - a
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
    denominator = d00 * d11 - d01 * d01
    ok = denominator > 0
    safe = np.where(ok, denominator, 1.0)
    w1 = np.where(ok, (d11 * d20 - d01 * d21) / safe, 0.0)
    w2 = np.where(ok, (d00 * d21 - d01 * d20) / safe, 0.0)
    w = np.clip(np.stack([1.0 - w1 - w2, w1, w2], axis=1), 0.0, None)
    total = w.sum(1, keepdims=True)
    w = np.where(total > 0, w / np.where(total > 0, total, 1.0), [1.0, 0.0, 0.0])
    at = w[:, :1] * a + w[:, 1:2] * b + w[:, 2:] * c
    return w, np.linalg.norm(points - at, axis=1)


def test_moved_vertices_take_the_closest_triangle_of_their_cluster():
    from meshgen import bumpy_torus
    from topstoc.core.carry.attributes import moved_vertices

    vertices, triangles = bumpy_torus(6000)
    result = Mesh(vertices, triangles).decimate(ratio=0.05, seed=3)  # quality mode: free vertices move
    moved = moved_vertices(vertices, triangles, result)
    still = np.all(result.vertices == vertices[result.kept], axis=1)
    assert np.array_equal(moved.face < 0, still) and still.sum() < 0.5 * len(still)
    assert np.array_equal(moved.weights[still], np.tile([1.0, 0.0, 0.0], (still.sum(), 1)))
    # brute force: every triangle with a corner in the vertex's cluster, the closest, lowest id on ties
    labels = np.asarray(result.labels)
    for v in moved.moved[:60]:
        candidates = np.flatnonzero((labels[triangles] == v).any(axis=1))
        corners = vertices[triangles[candidates]]
        point = np.repeat(result.vertices[v][None], len(candidates), axis=0)
        w, distance = _clamped_barycentric(point, corners[:, 0], corners[:, 1], corners[:, 2])
        best = np.flatnonzero(distance == distance.min())[0]
        assert moved.face[v] == candidates[best]
        assert moved.weights[v].tobytes() == w[best].tobytes()  # the same arithmetic, bit for bit


def test_moved_sources_read_from_the_prepared_mesh_are_the_arrays_ones():
    """moved_vertices_of reads the prepared mesh (its reordered vertices and faces) instead of the
    caller's arrays, so that a big decimation need not take them back: the same triangle and
    weights for every output vertex, on a flat grid (ties), a scan with holes and a torus, in both
    modes; a mesh that dropped a triangle takes the arrays' way."""
    import meshgen
    from topstoc.core.carry.attributes import moved_vertices, moved_vertices_of
    elephant = read_mesh(pathlib.Path(__file__).resolve().parents[1] / "data" / "open_boundary"
                         / "cgal_elephant-with-holes.off")
    moved = 0
    for vertices, triangles in (meshgen.bumpy_torus(20_000), (elephant.vertices, elephant.triangles),
                                meshgen.grid(40, 30)):
        mesh = Mesh(vertices, triangles)
        for mode, ratio in (("quality", 0.1), ("quality", 0.02), ("fast", 0.1)):
            result = mesh.decimate(ratio=ratio, mode=mode, seed=1)
            expected, found = moved_vertices(mesh.vertices, mesh.triangles, result), moved_vertices_of(mesh, result)
            np.testing.assert_array_equal(found.face, expected.face)
            np.testing.assert_array_equal(found.weights, expected.weights)
            moved += int((expected.face >= 0).sum())
    assert moved > 1000  # the comparison covered moved vertices, not only unmoved ones
    mesh = Mesh(vertices, np.vstack([triangles, [[0, 0, 1]]]))
    assert len(mesh.native.report["dropped_triangles"]) == 1
    result = mesh.decimate(ratio=0.2, mode="quality", seed=1)
    expected, found = moved_vertices(mesh.vertices, mesh.triangles, result), moved_vertices_of(mesh, result)
    np.testing.assert_array_equal(found.face, expected.face)
    np.testing.assert_array_equal(found.weights, expected.weights)
