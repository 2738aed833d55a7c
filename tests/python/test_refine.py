"""Quadric refinement (refine=f): TopStoc to f x the target, then quadric-ordered collapses.

Everything TopStoc guarantees must still hold (checked with tests/reference.py, independent of
the engine), the budget must be met, and the error against the input must drop.
"""

import pathlib

import numpy as np
import pytest

import meshgen
import reference
from test_decimate import SURFACES, check_output, load, region_invariants, sphere_with_regions
from topstoc.core import Mesh, hausdorff

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("path", SURFACES, ids=lambda p: p.name)
@pytest.mark.heavy
def test_topology_orientation_and_budget_kept(path):
    mesh = load(path)
    expected = reference.invariants(mesh.num_vertices, mesh.triangles)
    for ratio in (0.2, 0.05):
        for seed in range(3):
            for refine in (2, 6):
                r = mesh.decimate(ratio=ratio, seed=seed, refine=refine)
                check_output(mesh, r, expected)  # labels follow the collapses, no zero area
                plain = mesh.decimate(ratio=ratio, seed=seed, mode="fast", draft=True)
                # the budget: never above TopStoc's own count at this target (its plain pass: a
                # draft, see test_draft.py), and on the target unless the topology (or a border)
                # needs the vertices
                assert r.num_vertices <= max(plain.num_vertices, r.stats.target_vertices)
                assert r.stats.refine_vertices == r.stats.target_vertices
                if mesh.report().boundary_edges == 0 and mesh.num_vertices >= 1000:
                    assert r.num_vertices == r.stats.target_vertices, (ratio, seed, refine)


@pytest.mark.heavy
def test_refinement_lowers_the_error():
    for name in ("genus0/cgal_ChineseDragon-10kv.off", "genus_positive/cgal_turbine.off",
                 "genus0/cgal_fandisk.off"):
        v, t = reference.read_off(DATA / name)
        mesh = Mesh(v, t)
        for ratio in (0.1, 0.02):
            plain = mesh.decimate(ratio=ratio, seed=1, mode="fast")
            refined = mesh.decimate(ratio=ratio, seed=1)  # quality mode, the default
            assert refined.num_vertices <= max(plain.num_vertices, plain.stats.target_vertices)
            e_plain = hausdorff((v, t), plain, samples=100_000).symmetric
            e_refined = hausdorff((v, t), refined, samples=100_000).symmetric
            # measured: 1.5x to 35x lower mean; a refinement that did not help would fail here
            assert e_refined.mean < 0.7 * e_plain.mean, (name, ratio, e_plain.mean, e_refined.mean)
            # the max is not what the collapses minimise; it stays in the same range
            assert e_refined.max < 1.5 * e_plain.max, (name, ratio, e_plain.max, e_refined.max)


@pytest.mark.heavy
def test_refinement_leaves_no_thinner_worst_triangle_than_plain_topstoc():
    """The worst triangle (aspect ratio, thesis eq. 4.2, reference.py) of the quality mode is no
    worse than plain TopStoc's at the same target. The dragon has needles: the ends of input edges
    a ten-thousandth of the diagonal long, which the first pass keeps. The collapses' shape rule
    kept them and let them stretch (worst 7,949 against plain TopStoc's 2,470 at 10 %, 1,084
    against 611 at 1 %); with the rule's floor (collapser.cpp) it is 152. Plain TopStoc is the
    pass before any collapses (a draft): fast mode collapses a pass that ends above its target."""
    def worst_aspect(vertices, triangles):
        return float(reference.aspect_ratios(vertices, triangles).max())

    for name in ("genus0/cgal_ChineseDragon-10kv.off", "genus_positive/cgal_turbine.off",
                 "genus_positive/cgal_couplingdown.off"):
        mesh = Mesh(*reference.read_off(DATA / name))
        for ratio in (0.1, 0.05, 0.02, 0.01):
            plain = mesh.decimate(ratio=ratio, seed=1, mode="fast", draft=True)
            refined = mesh.decimate(ratio=ratio, seed=1)
            worst, reference_worst = worst_aspect(refined.vertices, refined.triangles), worst_aspect(plain.vertices, plain.triangles)
            assert worst <= reference_worst, (name, ratio, worst, reference_worst)


def test_borders_and_attributes_survive_refinement():
    v, t, regions = sphere_with_regions()
    mesh = Mesh(v, t)
    expected = region_invariants(len(v), t, regions)
    on_border = np.zeros(len(v), bool)
    edges = reference.undirected_edges(t)
    face_of_side = np.concatenate([np.arange(len(t))] * 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    e, f = edges[order], face_of_side[order]
    border_edges = e[0::2][regions[f[0::2]] != regions[f[1::2]]]
    on_border[border_edges.ravel()] = True
    for seed in range(4):
        plain = mesh.decimate(ratio=0.05, seed=seed, regions=regions, mode="fast")
        r = mesh.decimate(ratio=0.05, seed=seed, regions=regions, refine=4)
        out_regions = regions[r.face_source]
        assert region_invariants(r.num_vertices, r.triangles, out_regions) == expected
        # borders thin out only along themselves: every vertex on an output border is an
        # input border vertex
        out_edges = reference.undirected_edges(r.triangles)
        side_faces = np.concatenate([np.arange(len(r.triangles))] * 3)
        order = np.lexsort((out_edges[:, 1], out_edges[:, 0]))
        oe, of = out_edges[order], side_faces[order]
        out_border = oe[0::2][out_regions[of[0::2]] != out_regions[of[1::2]]]
        assert len(out_border) > 0 and on_border[r.kept[out_border.ravel()]].all()
        # and stay where they were: border vertices move only along their border, onto input
        # vertices, so seams and material borders are exact
        border_vertices = np.unique(out_border.ravel())
        np.testing.assert_array_equal(r.vertices[border_vertices], v[r.kept[border_vertices]])
        assert r.stats.refine_collapses > 0 and r.num_vertices < plain.num_vertices + 2
        corner_face, corner_slot = np.divmod(r.corner_source, 3)
        np.testing.assert_array_equal(t[corner_face, corner_slot], r.kept[r.triangles])
        np.testing.assert_array_equal(regions[corner_face], out_regions[:, None].repeat(3, 1))


def test_boundaries_are_kept():
    mesh = load(DATA / "open_boundary/cgal_elephant-with-holes.off")
    boundary = np.zeros(mesh.num_vertices, bool)
    edges = reference.undirected_edges(mesh.triangles)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    boundary[unique[counts == 1].ravel()] = True
    for seed in range(3):
        r = mesh.decimate(ratio=0.05, seed=seed, refine=4)
        check_output(mesh, r, reference.invariants(mesh.num_vertices, mesh.triangles))  # same holes
        # boundaries thin out only along themselves: output boundary vertices are input ones
        out_edges, counts = np.unique(reference.undirected_edges(r.triangles), axis=0, return_counts=True)
        out_boundary = out_edges[counts == 1].ravel()
        assert len(out_boundary) > 0 and boundary[r.kept[out_boundary]].all()
        # 106 holes need >= 318 vertices, more than the target: the rims sampled at 4x the
        # target first thin out to no more than plain TopStoc (its pass before collapses: a draft) keeps
        np.testing.assert_array_equal(r.vertices[out_boundary], mesh.vertices[r.kept[out_boundary]])
        plain = mesh.decimate(ratio=0.05, seed=seed, mode="fast", draft=True)
        assert r.num_vertices <= plain.num_vertices, (r.num_vertices, plain.num_vertices)


def test_guidance_redistributes_the_budget_in_both_modes():
    v, t = meshgen.icosphere(5)
    mesh = Mesh(v, t)
    rng = np.random.default_rng(5)
    u = np.zeros(len(v))
    keep = rng.choice(np.flatnonzero(v[:, 2] < 0.5), 25, replace=False)
    u[keep] = 1.0
    painted = v[:, 0] > 0.3
    u[painted & (u == 0)] = 0.6
    target = round(0.02 * len(v))
    counts = {}
    for mode in ("quality", "fast"):
        r = mesh.decimate(ratio=0.02, seed=3, guidance=u, mode=mode)
        assert set(keep) <= set(r.kept)  # control points are never collapsed
        check_output(mesh, r, reference.invariants(len(v), t))
        assert abs(r.num_vertices - target) <= 0.01 * target and r.stats.over_budget == 0
        # the painted cap (u = 0.6: 16 times the density) keeps vertices more densely
        area = painted.mean()
        density_painted = painted[r.kept].mean() / area
        density_rest = (~painted[r.kept]).mean() / (1 - area)
        assert density_painted > 4 * density_rest, (mode, density_painted, density_rest)
        counts[mode] = painted[r.kept].sum()
    # the same paint means the same in both modes: the painted region's share of the budget
    assert abs(counts["quality"] - counts["fast"]) <= max(3, 0.1 * counts["fast"]), counts
    unguided = mesh.decimate(ratio=0.02, seed=3)
    assert painted[r.kept].mean() > painted[unguided.kept].mean() + 0.2


def test_same_seed_identical_and_samples_restore():
    v, t, regions = sphere_with_regions()
    mesh = Mesh(v, t)
    u = np.where(v[:, 1] > 0.5, 0.5, 0.0)
    for placement in ("subsample", "filtered"):
        a = mesh.decimate(ratio=0.03, seed=11, regions=regions, placement=placement, refine=3, guidance=u)
        b = mesh.decimate(ratio=0.03, seed=11, regions=regions, placement=placement, refine=3, guidance=u)
        c = mesh.decimate_with_samples(a.samples, regions=regions, placement=placement,
                                       refine_vertices=a.stats.refine_vertices, guidance=u)
        assert a.stats.refine_collapses > 0
        for other in (b, c):
            for name in ("vertices", "triangles", "kept", "face_source", "corner_source", "labels", "samples"):
                np.testing.assert_array_equal(getattr(a, name), getattr(other, name), err_msg=name)


def test_tiny_targets_and_several_components():
    v, t = meshgen.disjoint(meshgen.torus(24, 12), meshgen.icosphere(3), meshgen.genus_slab(3, 2))
    mesh = Mesh(v, t)
    expected = reference.invariants(mesh.num_vertices, mesh.triangles)
    for target in (3, 30, 300):
        r = mesh.decimate(target_vertices=target, seed=target, refine=5)
        check_output(mesh, r, expected)


@pytest.mark.parametrize("refine", [-1, 0.5, float("nan"), float("inf"), True, "3"])
def test_bad_refine_values(refine):
    mesh = Mesh(*meshgen.icosphere(3))
    with pytest.raises(ValueError, match="refine must be 0"):
        mesh.decimate(ratio=0.1, refine=refine)
    with pytest.raises(ValueError, match="refine_vertices"):
        mesh.decimate_with_samples(np.arange(10), refine_vertices=-3)


@pytest.mark.heavy
def test_triangle_and_error_targets():
    v, t = reference.read_off(DATA / "genus0/cgal_fandisk.off")
    mesh = Mesh(v, t)
    r = mesh.decimate(target_triangles=2000, refine=4, placement="filtered")
    assert abs(r.num_triangles - 2000) <= 20
    # error-bounded: the bound holds, measured independently of the search, and the refined
    # result needs far fewer vertices than plain TopStoc (measured: 592 vs 5996)
    bound = 0.001
    refined = mesh.decimate(max_error=bound, relative=True, refine=8, placement="filtered")
    plain = mesh.decimate(max_error=bound, relative=True, mode="fast")
    diagonal = np.linalg.norm(v.max(axis=0) - v.min(axis=0))
    measured = hausdorff((v, t), refined, samples=200_000).symmetric.max
    assert measured <= 1.02 * bound * diagonal
    assert refined.num_vertices < 0.5 * plain.num_vertices


def test_a_dead_end_goes_on_where_only_the_point_failed_the_shape_rule():
    """The spider with its UV seams as borders, at 27 triangles: its collapses ran dry at 197, every
    one left failing a check, some only because their quadric-optimal point would leave a triangle
    too thin where keeping the survivor in place would not. Those go on once nothing else can
    (measured: 167 triangles), with the same topology and the seams kept on their input course."""
    from topstoc.core import read_mesh
    from topstoc.core.carry.attributes import uv_seam_edges
    data = read_mesh(DATA / "uv_materials" / "spider" / "spider.obj")
    triangles = data.triangles.astype(np.int64)
    seams = uv_seam_edges(triangles, data.corner_uvs)
    mesh = Mesh(data.vertices, triangles)
    r = mesh.decimate(target_triangles=27, seed=0, borders=seams)
    assert r.num_triangles <= 175, r.num_triangles
    assert r.stats.target_missed is not None  # (still far above 27: the seams' own floor)
    assert reference.invariants(r.num_vertices, r.triangles) == reference.invariants(len(data.vertices), triangles)
    assert reference.degenerate_or_duplicate(r.triangles) == (0, 0)
    assert r.stats.topology_kept and not any(v for k, v in r.stats.output_check.items() if k != "zero_area")
    # every seam vertex left is an input seam vertex, where it was
    on_seam = np.zeros(len(data.vertices), bool)
    on_seam[seams.ravel()] = True
    kept_on_seam = on_seam[r.kept]
    assert kept_on_seam.sum() > 0
    np.testing.assert_array_equal(r.vertices[kept_on_seam], data.vertices[r.kept[kept_on_seam]])
