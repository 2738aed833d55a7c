"""TopStoc decimation: topology, budget, guidance, borders, determinism and bad input (most in
the fast mode, the thesis' TopStoc; topology also in the quality mode, see test_refine.py).

Topology is checked with tests/reference.py (scipy connected components), never with the
engine's own checks.
"""

import pathlib

import numpy as np
import pytest

import meshgen
from threads import outputs_by_thread_count
import reference
from topstoc.core import Mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
SURFACES = sorted(DATA.glob("genus0/*.off")) + sorted(DATA.glob("genus_positive/*.off")) + [
    DATA / "open_boundary/cgal_elephant-with-holes.off", DATA / "open_boundary/cgal_mushroom.off"]
SEEDS = range(20)
RATIOS = (0.2, 0.05, 0.01)


def load(path):
    return Mesh(*reference.read_off(path))


def check_output(mesh, result, expected_invariants):
    """The decimated mesh is clean and keeps every component's topology."""
    tri = result.triangles
    degenerate, duplicates = reference.degenerate_or_duplicate(tri)
    assert degenerate == 0 and duplicates == 0
    # orientation kept: no directed edge twice (so every manifold edge is used once each way)
    directed = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    assert len(np.unique(directed, axis=0)) == len(directed)
    assert reference.invariants(result.num_vertices, tri) == expected_invariants
    assert np.isfinite(result.vertices).all()
    # zero-area triangles: none on smooth meshes (test_budget.py); where an input's coincident
    # or collinear vertices leave some that no allowed collapse removes (measured: 0-5 in 36
    # decimations of a CAD part and of a mesh whose holes touch), the result reports them
    p = result.vertices[tri]
    flat = np.flatnonzero(np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1) == 0)
    assert len(flat) == result.stats.issues_remaining["sliver"]
    # plain TopStoc (fast mode, subsample): every output vertex is the input vertex it stands
    # for; quality mode moves free vertices (placement, collapses)
    if result.parameters.get("placement") == "subsample" and not result.parameters.get("refine"):
        np.testing.assert_array_equal(result.vertices, mesh.vertices[result.kept])
    # each triangle's corners are the samples of its source triangle's clusters
    source = mesh.triangles[result.face_source]
    np.testing.assert_array_equal(result.labels[source], tri)


def plain_count(mesh, ratio, seed):
    """Vertices the plain TopStoc pass keeps (a draft: fast mode collapses a pass above its target)."""
    return mesh.decimate(ratio=ratio, seed=seed, mode="fast", draft=True).num_vertices


@pytest.mark.parametrize("path", SURFACES, ids=lambda p: p.name)
@pytest.mark.heavy
def test_topology_kept_for_every_seed_and_ratio(path):
    mesh = load(path)
    expected = reference.invariants(mesh.num_vertices, mesh.triangles)
    assert all(manifold and orientable for _, _, manifold, orientable in expected)
    for mode, seeds in (("fast", SEEDS), ("quality", SEEDS[:5])):
        for ratio in RATIOS:
            for seed in seeds:
                result = mesh.decimate(ratio=ratio, seed=seed, mode=mode)
                check_output(mesh, result, expected)
                assert result.stats.topology_kept
                target = result.stats.target_vertices
                miss = result.num_vertices - target
                if mesh.num_vertices >= 1000:
                    # the budget holds within 1 %, unless the topology needs more samples than
                    # the target allows: then the excess is the repairs the result reports and the
                    # holes' vertices the draw forced (or below it by the collapses that removed
                    # zero-area triangles); quality mode keeps no more than the plain TopStoc pass
                    # (a draft) where the topology stops it
                    assert abs(miss) <= 0.01 * target or 0 < miss <= result.stats.repairs + result.stats.loop_forced \
                        or 0 < -miss <= 0.01 * target + result.stats.refine_collapses \
                        or (mode == "quality" and result.stats.over_budget_reason == "topology"
                            and result.num_vertices <= plain_count(mesh, ratio, seed)), \
                        (mode, ratio, seed, miss)


@pytest.mark.heavy
def test_big_shared_meshes_keep_topology(shared_meshes):
    for name in ("genus0/cgal_bunny00.off", "genus0/cgal_armadillo.off"):
        mesh = load(shared_meshes / name)
        expected = reference.invariants(mesh.num_vertices, mesh.triangles)
        for ratio in RATIOS:
            for seed in range(3):
                result = mesh.decimate(mode="fast", ratio=ratio, seed=seed)
                check_output(mesh, result, expected)
                assert abs(result.num_vertices - result.stats.target_vertices) <= 0.01 * result.stats.target_vertices


def test_several_components_and_tiny_targets():
    v, t = meshgen.disjoint(meshgen.torus(24, 12), meshgen.icosphere(3), meshgen.genus_slab(3, 2))
    mesh = Mesh(v, t)
    expected = reference.invariants(mesh.num_vertices, mesh.triangles)
    for target in (3, 30, 300):
        result = mesh.decimate(mode="fast", target_vertices=target, seed=target)
        check_output(mesh, result, expected)
        # far too small for three components with genus 1 and 3: the engine adds what they need
        if target == 3:
            assert result.num_vertices > 3 and result.stats.repairs > 0


def region_invariants(num_vertices, triangles, regions):
    return {r: reference.invariants(num_vertices, triangles[regions == r]) for r in np.unique(regions)}


def sphere_with_regions():
    v, t = meshgen.icosphere(4)
    centroid = v[t].mean(axis=1)
    regions = (centroid[:, 0] > 0.2).astype(np.int32) + 2 * (centroid[:, 1] > -0.3)
    return v, t, regions


def test_regions_are_never_crossed_and_survive():
    v, t, regions = sphere_with_regions()
    mesh = Mesh(v, t)
    expected = region_invariants(len(v), t, regions)
    regions_of_vertex = [set() for _ in range(len(v))]
    for f, (a, b, c) in enumerate(t):
        for x in (a, b, c):
            regions_of_vertex[x].add(int(regions[f]))
    for ratio in RATIOS:
        for seed in range(5):
            r = mesh.decimate(mode="fast", ratio=ratio, seed=seed, regions=regions)
            out_regions = regions[r.face_source]
            # each region decimates to a surface of the same topology, with the same borders
            got = region_invariants(r.num_vertices, r.triangles, out_regions)
            assert got == expected
            # no cluster crosses a border: a vertex's sample touches every region the vertex touches
            for vertex, output in enumerate(r.labels):
                assert regions_of_vertex[vertex] <= regions_of_vertex[r.kept[output]]
            # attributes come from a corner of the kept vertex in the output triangle's region
            corner_face, corner_slot = np.divmod(r.corner_source, 3)
            np.testing.assert_array_equal(t[corner_face, corner_slot], r.kept[r.triangles])
            np.testing.assert_array_equal(regions[corner_face], out_regions[:, None].repeat(3, 1))


def test_flagged_border_edges_act_like_region_borders():
    v, t, regions = sphere_with_regions()
    mesh = Mesh(v, t)
    edges = reference.undirected_edges(t)
    face_of_side = np.concatenate([np.arange(len(t))] * 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    e, f = edges[order], face_of_side[order]
    same = np.all(e[0::2] == e[1::2], axis=1)
    assert same.all()  # closed manifold: every edge has exactly two sides
    border = e[0::2][regions[f[0::2]] != regions[f[1::2]]]
    a = mesh.decimate(mode="fast", ratio=0.05, seed=4, regions=regions)
    b = mesh.decimate(mode="fast", ratio=0.05, seed=4, borders=border)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    np.testing.assert_array_equal(a.kept, b.kept)


def test_control_points_kept_and_excluded_vertices_absent():
    v, t = meshgen.icosphere(4)
    mesh = Mesh(v, t)
    rng = np.random.default_rng(5)
    u = np.zeros(len(v))
    keep = rng.choice(np.flatnonzero(v[:, 2] < 0.5), 25, replace=False)
    u[keep] = 1.0
    drop = np.flatnonzero(v[:, 2] > 0.7)
    u[drop] = -1.0
    for seed in range(5):
        r = mesh.decimate(mode="fast", ratio=0.02, seed=seed, guidance=u)
        assert set(keep) <= set(r.kept)
        assert not set(drop) & set(r.kept)
        check_output(mesh, r, reference.invariants(len(v), t))


def test_painted_region_keeps_more_vertices():
    v, t = meshgen.icosphere(5)
    mesh = Mesh(v, t)
    painted = v[:, 0] > 0
    u = np.where(painted, 0.5, 0.0)
    r = mesh.decimate(mode="fast", ratio=0.02, seed=1, guidance=u)
    inside = painted[r.kept].sum()
    outside = (~painted[r.kept]).sum()
    # p = k + (1 - k) 0.5 ~ 0.51 vs k = 0.02 per vertex: far more than 5x denser
    assert inside > 5 * outside


def test_view_dependent_keeps_the_front():
    from topstoc.core import View
    v, t = meshgen.icosphere(5)
    mesh = Mesh(v, t)
    # the silhouette band is kept (p = 1, about 300 vertices): a budget that leaves room for more
    r = mesh.decimate(mode="fast", ratio=0.15, seed=2, view=View(eye=[0, 0, 10], back_ratio=0.1))
    front = v[r.kept][:, 2] > 0.3
    back = v[r.kept][:, 2] < -0.3
    assert front.sum() > 5 * back.sum()
    check_output(mesh, r, reference.invariants(len(v), t))


def test_same_seed_identical_arrays_and_samples_restore():
    v, t, regions = sphere_with_regions()
    mesh = Mesh(v, t)
    for placement in ("subsample", "filtered"):
        a = mesh.decimate(mode="fast", ratio=0.03, seed=11, regions=regions, placement=placement)
        b = mesh.decimate(mode="fast", ratio=0.03, seed=11, regions=regions, placement=placement)
        c = mesh.decimate_with_samples(a.samples, regions=regions, placement=placement)
        for other in (b, c):
            for name in ("vertices", "triangles", "kept", "face_source", "corner_source", "labels", "samples"):
                np.testing.assert_array_equal(getattr(a, name), getattr(other, name), err_msg=name)
    assert not np.array_equal(mesh.decimate(mode="fast", ratio=0.03, seed=12).kept, a.kept)


SERIAL_PARALLEL_SCRIPT = """
import hashlib, sys
sys.path[:0] = sys.argv[1:3]
import meshgen
from topstoc.core import Mesh
mesh = Mesh(*meshgen.icosphere(7))  # 164k vertices: above the parallel threshold
digest = hashlib.sha256()
for options in (dict(ratio=0.2), dict(ratio=0.02), dict(ratio=0.05, refine=4, placement="filtered"),
                dict(ratio=0.1, density="off")):
    r = mesh.decimate(mode="fast", seed=3, **{"density": "adaptive", **options})
    for a in (r.vertices, r.triangles, r.kept, r.corner_source, r.labels, r.samples):
        digest.update(a.tobytes())
    digest.update(r.stats.expected_vertices.hex().encode())  # a sum over every vertex: to the bit
r = mesh.decimate(mode="quality", ratio=0.01, seed=3)  # quadrics summed in blocks of vertices
digest.update(r.vertices.tobytes() + r.triangles.tobytes())
print(digest.hexdigest())
"""


@pytest.mark.heavy
def test_serial_and_parallel_runs_agree():
    assert len(set(outputs_by_thread_count(SERIAL_PARALLEL_SCRIPT).values())) == 1


SUMS_SCRIPT = """
import sys
sys.path[:0] = sys.argv[1:3]
import meshgen
from topstoc.core.support.native import engine
vertices, triangles = meshgen.icosphere(7)  # 327,680 triangles: above the parallel threshold
vertices = vertices * (1 + 0.01 * ((vertices * 1e4) % 1))  # uneven, so the order of sums shows
stats = engine.aspect_ratio_stats(vertices, triangles)
surface = engine.Surface(vertices, triangles)
print(stats["mean"].hex(), stats["max"].hex(), engine.step_for_sample_count(surface, 3000000).hex())
"""


@pytest.mark.heavy
def test_parallel_sums_are_the_same_to_the_bit():
    # The aspect-ratio mean was an OpenMP reduction: its last bits followed the thread count.
    # (Threads follow the free cores: on a busy machine "2" may run on fewer; the C++ test
    # test_ordered_sum.cpp sets the team size itself.)
    outputs = outputs_by_thread_count(SUMS_SCRIPT, counts=("1", "2"))
    assert outputs["1"] == outputs["2"], outputs


def test_concurrent_calls_on_one_mesh_agree_with_serial_ones():
    # The live preview decimates on two threads at once; each call then gets its share of the
    # cores (and the importance table is shared): results must be those of one call at a time.
    from concurrent.futures import ThreadPoolExecutor

    mesh = Mesh(*meshgen.icosphere(7))  # above the parallel threshold
    ratios = (0.2, 0.05, 0.1, 0.02)
    with ThreadPoolExecutor(max_workers=2) as pool:
        together = list(pool.map(lambda r: mesh.decimate(mode="fast", ratio=r, seed=5), ratios))
    for ratio, got in zip(ratios, together):
        alone = mesh.decimate(mode="fast", ratio=ratio, seed=5)
        for name in ("triangles", "kept", "labels", "samples"):
            np.testing.assert_array_equal(getattr(got, name), getattr(alone, name), err_msg=f"{ratio} {name}")


def test_triangle_target_within_one_percent():
    mesh = load(DATA / "genus0/cgal_fandisk.off")
    for target in (500, 2000, 6000):
        r = mesh.decimate(mode="fast", target_triangles=target, seed=1)
        assert abs(r.num_triangles - target) <= 0.01 * target


def test_filtered_placement_moves_surface_samples_only():
    v, t = meshgen.grid(30, 30)
    v[:, 2] = np.sin(v[:, 0] / 4) * np.cos(v[:, 1] / 5) * 3
    mesh = Mesh(v, t)
    plain = mesh.decimate(mode="fast", ratio=0.05, seed=2)
    filtered = mesh.decimate(mode="fast", ratio=0.05, seed=2, placement="filtered")
    np.testing.assert_array_equal(plain.triangles, filtered.triangles)
    moved = np.linalg.norm(filtered.vertices - plain.vertices, axis=1)
    border = (v[plain.kept, 0] % 30 == 0) | (v[plain.kept, 1] % 30 == 0)
    assert np.all(moved[border] == 0)       # boundary samples stay (borders keep their positions)
    assert np.count_nonzero(moved[~border]) > 0.5 * (~border).sum()
    # and no sample leaves its cluster's radius
    for i, s in enumerate(plain.kept):
        members = v[plain.labels == i]
        radius = np.linalg.norm(members - v[s], axis=1).max()
        assert moved[i] <= radius + 1e-9


def test_nonmanifold_input_is_decimated_without_damage():
    # two tetrahedra sharing one edge (the edge has four triangles), plus a fin
    v = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 0.5, 1], [0.5, -1, 0], [0.5, -0.5, 1],
                  [0.5, 0.2, -1]], dtype=float)
    t = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2],
                  [0, 1, 4], [0, 5, 1], [1, 5, 4], [0, 4, 5], [0, 1, 6]])
    mesh = Mesh(v, t)
    assert mesh.report().nonmanifold_edges == 1
    r = mesh.decimate(mode="fast", target_vertices=4, seed=0)
    degenerate, duplicates = reference.degenerate_or_duplicate(r.triangles)
    assert degenerate == 0 and duplicates == 0
    # the non-manifold edge is a corner-to-corner feature: both ends stay
    assert {0, 1} <= set(r.kept)


@pytest.mark.parametrize("kwargs, message", [
    (dict(ratio=0), r"ratio must lie in \(0, 1\]"),
    (dict(ratio=1.5), r"ratio must lie in \(0, 1\]"),
    (dict(ratio=float("nan")), r"ratio must lie in \(0, 1\]"),
    (dict(target_vertices=0), r"outside \[1, 642\]"),
    (dict(target_vertices=10**6), r"outside \[1, 642\]"),
    (dict(target_vertices=2.5), "must be an integer"),
    (dict(target_triangles=0), r"outside \[1, 1280\]"),
    (dict(ratio=0.1, target_vertices=10), "exactly one target"),
    (dict(), "exactly one target"),
    (dict(ratio=0.1, seed=-1), "seed"),
    (dict(ratio=0.1, placement="moved"), "placement"),
    (dict(ratio=0.1, regions=np.zeros(7, dtype=np.int32)), "regions has 7 entries"),
    (dict(ratio=0.1, borders=np.array([[0, 600]])), r"border edge 0 \(0, 600\) is not an edge"),
    (dict(ratio=0.1, borders=np.array([[0, 10**6]])), "is not an edge"),
])
def test_bad_decimation_arguments(kwargs, message):
    mesh = Mesh(*meshgen.icosphere(3))
    with pytest.raises(ValueError, match=message):
        mesh.decimate(mode="fast", **kwargs)


@pytest.mark.parametrize("samples, message", [
    (np.array([], dtype=np.int64), "empty"),
    (np.array([0, 1, 700]), "outside"),
    (np.array([0, 5, 5]), "sampled twice"),
    (np.array([0.5]), "integer"),
])
def test_bad_sample_lists(samples, message):
    mesh = Mesh(*meshgen.icosphere(3))
    with pytest.raises(ValueError, match=message):
        mesh.decimate_with_samples(samples)


def test_creases_become_borders_on_hard_surface_models():
    mesh = load(DATA / "genus0/cgal_fandisk.off")
    import math
    layout = mesh.feature_layout(feature_angle=math.radians(40))
    assert layout.crease_edges > 500 and layout.corners > 0
    plain = mesh.decimate(mode="fast", ratio=0.05, seed=1)
    creased = mesh.decimate(mode="fast", ratio=0.05, seed=1, feature_angle=math.radians(40))
    target = plain.stats.target_vertices
    for result in (plain, creased):  # still the exact budget
        assert abs(result.num_vertices - target) <= max(1, 0.01 * target)
    # creases are sampled as curves: a large share of the kept vertices lie on them
    crease_vertices = np.unique(mesh.native.edges[layout.edge_feature.astype(bool)])
    assert np.isin(creased.kept, crease_vertices).sum() > 0.3 * creased.num_vertices
    check_output(mesh, creased, reference.invariants(mesh.num_vertices, mesh.triangles))
    # and the result stays closer to the original (mean symmetric Hausdorff distance)
    from topstoc.core.api.hausdorff import hausdorff
    plain_error = hausdorff(mesh, plain, samples=50000).symmetric.mean
    creased_error = hausdorff(mesh, creased, samples=50000).symmetric.mean
    assert creased_error < 0.8 * plain_error


def test_fast_path_gives_the_same_mesh():
    # thesis 4.1.1: candidate faces collected during the flood instead of a scan of all faces
    v, t, regions = sphere_with_regions()
    mesh = Mesh(v, t)
    for ratio in (0.2, 0.03, 0.005):
        fast = mesh.decimate(mode="fast", ratio=ratio, seed=5, regions=regions, fast_path=True)
        full = mesh.decimate(mode="fast", ratio=ratio, seed=5, regions=regions, fast_path=False)
        assert fast.stats.fast_path and not full.stats.fast_path
        for name in ("triangles", "kept", "face_source", "corner_source", "labels", "samples"):
            np.testing.assert_array_equal(getattr(fast, name), getattr(full, name), err_msg=name)
    # off unless asked for: the full scan is the faster one in this engine (see decimate.hpp)
    assert not mesh.decimate(mode="fast", ratio=0.03, seed=5).stats.fast_path


def test_old_target_keywords_still_work_with_a_warning():
    mesh = Mesh(*meshgen.icosphere(3))
    for old, new in (("vertices", "target_vertices"), ("triangles", "target_triangles")):
        with pytest.warns(DeprecationWarning, match=f"use {new}="):
            before = mesh.decimate(**{old: 100}, seed=2)
        after = mesh.decimate(**{new: 100}, seed=2)
        np.testing.assert_array_equal(before.vertices, after.vertices)
        np.testing.assert_array_equal(before.triangles, after.triangles)
        with pytest.raises(ValueError, match=f"give {new} only"):
            mesh.decimate(**{old: 100, new: 100})
