"""Sampling probabilities (docs/design.md §2.2) and the draw: formulas, exact budget, inclusion rates,
determinism and density control."""

import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import shortest_path

import meshgen
import reference
from topstoc.core import Box, Mesh, View, sampling_probabilities


@pytest.fixture(scope="module")
def sphere():
    return Mesh(*meshgen.icosphere(4))


@pytest.fixture(scope="module")
def slab():
    return Mesh(*meshgen.genus_slab(2, scale=3))


def base_probability(mesh, rate, adaptivity, floor=0.25):
    """docs/design.md §2.2 without guidance, recomputed from the independent weights."""
    x = reference.importance_weights(mesh.vertices, mesh.triangles)
    q = np.maximum(floor, 1 + adaptivity * (x / x.mean() - 1))
    return np.clip(rate * q, 0, 1)


@pytest.mark.parametrize("adaptivity", [0.0, 0.5, 1.0])
def test_probability_without_guidance_follows_spec(slab, adaptivity):
    p = sampling_probabilities(slab, 0.1, adaptivity=adaptivity)
    np.testing.assert_allclose(p, base_probability(slab, 0.1, adaptivity), atol=1e-9)
    if adaptivity == 0:
        assert np.allclose(p, 0.1)


def test_flat_regions_keep_a_floor():
    # adaptivity 1 would give flat vertices probability 0 (x = 0): the tweak keeps them at floor * k
    slab = Mesh(*meshgen.genus_slab(2, scale=6))
    p = sampling_probabilities(slab, 0.1, adaptivity=1.0, flat_floor=0.3)
    flat = reference.importance_weights(slab.vertices, slab.triangles) < 1e-12
    assert flat.sum() > 100
    np.testing.assert_allclose(p[flat], 0.03)


def test_guidance_formulas(sphere):
    n = sphere.num_vertices
    rng = np.random.default_rng(3)
    u = rng.choice([-1.0, -0.5, 0.0, 0.25, 1.0], size=n)
    p = sampling_probabilities(sphere, 0.2, adaptivity=0.0, guidance=u)
    k = 0.2
    # a density multiplier ((1 + u) / (1 - u))^2; u = 1 a control point, u = -1 never sampled
    with np.errstate(divide="ignore"):
        multiplier = ((1 + u) / (1 - u)) ** 2
    expected = np.where(u >= 1, 1.0, np.where(u <= -1, 0.0, np.minimum(1.0, k * multiplier)))
    np.testing.assert_allclose(p, expected, atol=1e-12)
    assert np.all(p[u == 1] == 1) and np.all(p[u == -1] == 0)


def test_boxes_set_guidance_inside(sphere):
    box = Box.from_center_size([0.5, 0.5, 0.5], [0.5, 0.5, 0.5], 1.0)
    p = sampling_probabilities(sphere, 0.1, adaptivity=0.0, boxes=[box])
    inside = np.all(np.abs(sphere.vertices - 0.5) <= 0.5, axis=1)
    assert inside.sum() > 10
    assert np.all(p[inside] == 1.0) and np.allclose(p[~inside], 0.1)
    # later boxes win
    drop = Box.from_center_size([0.5, 0.5, 0.5], [0.5, 0.5, 0.5], -1.0)
    p = sampling_probabilities(sphere, 0.1, adaptivity=0.0, boxes=[box, drop])
    assert np.all(p[inside] == 0.0)


def test_view_back_faces_silhouette_and_frustum(sphere):
    direction = np.array([0.0, 0.0, -1.0])  # looking down -z: the +z hemisphere faces the camera
    angle = math.radians(30)
    view = View(direction=direction, back_ratio=0.2, silhouette_angle=angle, silhouette_falloff=0.0)
    p = sampling_probabilities(sphere, 0.1, adaptivity=0.0, view=view)
    facing = sphere.normals @ -direction
    band = (1 - math.cos(angle)) / 2
    silhouette = np.abs(facing) <= band
    np.testing.assert_allclose(p[silhouette], 1.0)
    np.testing.assert_allclose(p[(facing > band)], 0.1)
    np.testing.assert_allclose(p[(facing < -band)], 0.02)
    # an orthographic frustum that only sees x > 0
    vp = np.eye(4)
    vp[0, 0], vp[0, 3] = 2.0, -1.0  # x in [0, 1] -> clip x in [-1, 1]
    vp[2, 2] = 0.1                  # keep z inside
    view = View(direction=direction, back_ratio=1.0, silhouette_angle=0.0, silhouette_falloff=0.0,
                view_projection=vp, outside_probability=0.01)
    p = sampling_probabilities(sphere, 0.1, adaptivity=0.0, view=view)
    outside = sphere.vertices[:, 0] < -1e-9
    inside = (sphere.vertices[:, 0] > 1e-9) & (np.abs(facing) > 1e-9)  # (facing 0 is the silhouette)
    assert np.all(p[outside] <= 0.01) and np.allclose(p[inside], 0.1)


def test_borders_are_sampled_as_curves():
    v, t = meshgen.grid(20, 20)
    mesh = Mesh(v, t)
    p = sampling_probabilities(mesh, 0.04, adaptivity=0.0)
    boundary = (v[:, 0] == 0) | (v[:, 0] == 20) | (v[:, 1] == 0) | (v[:, 1] == 20)
    # 1-D borders keep the spacing of the 2-D samples: sqrt of the rate; boundary corners of a
    # grid are ordinary curve vertices (one boundary loop, no junction)
    np.testing.assert_allclose(p[boundary], 0.2)
    np.testing.assert_allclose(p[~boundary], 0.04)


@pytest.mark.parametrize("target", [12, 100, 700, 2000])
def test_exact_budget_without_guidance(sphere, target):
    for seed in range(5):
        result = sphere.decimate(mode="fast", target_vertices=target, seed=seed)
        assert abs(result.num_vertices - target) <= max(1, 0.005 * target)
        assert not result.stats.guided


def test_guided_draw_keeps_the_budget(sphere):
    # paint redistributes the budget: the rate is solved so the guided probabilities sum to the
    # target (128 of 2562 here), and the draw takes exactly that many
    u = np.where(sphere.vertices[:, 2] > 0.3, 0.6, -0.4)
    result = sphere.decimate(ratio=0.05, seed=2, guidance=u, mode="fast")
    target = round(0.05 * sphere.num_vertices)
    assert result.stats.guided
    assert result.stats.selected == target
    p = sampling_probabilities(sphere, result.stats.rate, guidance=u)
    assert result.stats.expected_vertices == pytest.approx(p.sum())
    assert abs(p.sum() - target) <= 0.5
    # the painted part is sampled (0.6 / -0.4)-times denser: multipliers 16 and 0.18
    painted = sphere.vertices[:, 2] > 0.3
    assert p[painted].mean() == pytest.approx(min(1.0, 16 * result.stats.rate) * 1.0, rel=0.3)


def test_inclusion_frequencies_match_probabilities():
    mesh = Mesh(*meshgen.icosphere(3))
    u = np.where(mesh.vertices[:, 0] > 0, 0.5, -0.5)  # multipliers 9 and 1/9, adaptivity 0
    counts = np.zeros(mesh.num_vertices)
    runs = 300
    for seed in range(runs):
        r = mesh.decimate(ratio=0.1, seed=seed, adaptivity=0.0, guidance=u, mode="fast")
        counts[r.samples[:r.stats.selected]] += 1
    p = sampling_probabilities(mesh, r.stats.rate, adaptivity=0.0, guidance=u)
    frequency = counts / runs
    for group in (u > 0, u < 0):
        assert frequency[group].mean() == pytest.approx(p[group].mean(), abs=0.01)


def test_same_seed_same_draw_other_seed_other_draw(sphere):
    a = sphere.decimate(mode="fast", ratio=0.05, seed=7)
    b = sphere.decimate(mode="fast", ratio=0.05, seed=7)
    c = sphere.decimate(mode="fast", ratio=0.05, seed=8)
    np.testing.assert_array_equal(a.samples, b.samples)
    assert not np.array_equal(a.samples, c.samples)


def hop_distances(mesh, sources):
    e = np.unique(reference.undirected_edges(mesh.triangles), axis=0)
    n = mesh.num_vertices
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    return shortest_path(graph, directed=False, unweighted=True, indices=sources)


def test_uniform_density_keeps_samples_apart(sphere):
    result = sphere.decimate(mode="fast", ratio=0.02, seed=1, density="uniform", density_rings=3, adaptivity=0.0)
    drawn = result.samples[:result.stats.selected]
    assert result.stats.density_rejected > 0
    d = hop_distances(sphere, drawn)[:, drawn]
    np.fill_diagonal(d, np.inf)
    assert d.min() > 3
    # without density control, some samples do come that close
    plain = sphere.decimate(mode="fast", ratio=0.02, seed=1, adaptivity=0.0)
    drawn = plain.samples[:plain.stats.selected]
    d = hop_distances(sphere, drawn)[:, drawn]
    np.fill_diagonal(d, np.inf)
    assert d.min() <= 3


def test_adaptive_density_uses_smaller_rings_on_detail():
    # eps_big = 4 where x < mean (flat), eps_small = 2 where x > mean (detail)
    slab = Mesh(*meshgen.genus_slab(2, scale=6))
    result = slab.decimate(mode="fast", ratio=0.02, seed=3, adaptivity=0.0, density="adaptive", density_rings=4,
                           density_ratio=2.0)
    drawn = result.samples[:result.stats.selected]
    x = slab.weights
    d = hop_distances(slab, drawn)[:, drawn]
    np.fill_diagonal(d, np.inf)
    detail = x[drawn] > x.mean()
    nearest = d.min(axis=1)
    assert detail.sum() > 5 and (~detail).sum() > 5
    # a sample blocks its own rings: detail ones 2, flat ones 4 (so flat pairs are > 4 apart)
    assert np.all(nearest > 2)
    flat_pairs = d[np.ix_(~detail, ~detail)]
    assert flat_pairs.min() > 4
    assert nearest[~detail].mean() > nearest[detail].mean()


def test_density_control_improves_mean_aspect_ratio():
    mesh = Mesh(*meshgen.icosphere(5))
    plain = [mesh.decimate(mode="fast", ratio=0.02, seed=s).aspect_ratio()["mean"] for s in range(8)]
    spaced = [mesh.decimate(mode="fast", ratio=0.02, seed=s, density="uniform").aspect_ratio()["mean"] for s in range(8)]
    assert np.mean(spaced) < np.mean(plain)


@pytest.mark.parametrize("options, message", [
    (dict(adaptivity=1.5), "adaptivity"),
    (dict(flat_floor=-0.1), "flat_floor"),
    (dict(density="blue"), "density"),
    (dict(density_ratio=0.5, density="adaptive"), "density_ratio"),
    (dict(guidance=np.zeros(5)), "guidance"),
    (dict(guidance=np.full(2562, 2.0)), "must lie in"),
    (dict(guidance=np.full(2562, np.nan)), "must lie in"),
])  # View and Box refuse bad fields when made: tests/python/test_params.py
def test_bad_sampling_parameters(options, message):
    mesh = Mesh(*meshgen.icosphere(4))
    with pytest.raises(ValueError, match=message):
        mesh.decimate(mode="fast", ratio=0.1, **options)
