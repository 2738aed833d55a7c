"""topstoc.core.api.guidance: the documented guidance rules, checked against brute force."""

import itertools

import numpy as np
import pytest

from topstoc.core.api import guidance as rules

import meshgen


def test_colour_levels_round_trip_and_convention():
    for name, u in rules.GUIDANCE_LEVELS.items():
        assert rules.color_to_guidance(rules.guidance_color(u)[None])[0] == pytest.approx(u)
    orange, blue, grey = [1.0, 0.5, 0.0], [0.0, 0.5, 1.0], [0.5, 0.5, 0.5]
    u = rules.color_to_guidance(np.array([orange, blue, grey, [1, 1, 1], [0, 0, 0]]))
    np.testing.assert_allclose(u, [1, -1, 0, 0, 0])


def test_srgb_curve_round_trips():
    x = np.linspace(0, 1, 101)
    np.testing.assert_allclose(rules.linear_to_srgb(rules.srgb_to_linear(x)), x, atol=1e-12)
    assert rules.srgb_to_linear(0.5) == pytest.approx(0.2140, abs=1e-4)


@pytest.mark.parametrize("mapping, expected", [("DETAIL", [0, 0.25, 1, 0]), ("SIGNED", [-1, -0.5, 1, 0]),
                                               ("DECIMATE", [1, 0.75, 0, 0])])
def test_vertex_group_mappings(mapping, expected):
    u = rules.vertex_group_guidance([0.0, 0.25, 1.0, 0.7], [True, True, True, False], mapping)
    np.testing.assert_allclose(u, expected)
    with pytest.raises(ValueError, match="mapping"):
        rules.vertex_group_guidance([0.0], [True], "OTHER")


def test_combine_rules():
    a = np.array([0.5, 1.0, -1.0, 0.6, 0.0, 1.0])
    b = np.array([0.5, -1.0, 0.2, 0.6, 0.0, 0.0])
    u = rules.combine([(a, 1.0), (b, 1.0)], 6)
    #                sum clip, keep beats drop, drop, clipped, neutral, keep
    np.testing.assert_allclose(u, [1.0, 1.0, -1.0, 1.0, 0.0, 1.0])
    u = rules.combine([(a, 0.5)], 6)          # half strength: no hard decisions
    np.testing.assert_allclose(u, a / 2)
    assert rules.combine([], 6) is None
    with pytest.raises(ValueError, match="shape"):
        rules.combine([(np.zeros(3), 1.0)], 6)


def test_material_guidance_takes_the_largest_slot_weight():
    v, f = meshgen.grid(4, 4)
    slot = (np.arange(len(f)) >= len(f) // 2).astype(int)
    u = rules.material_guidance(len(v), f, slot, [-1.0, 0.5])
    for vertex in range(len(v)):
        slots = set(slot[np.any(f == vertex, axis=1)].tolist())
        assert u[vertex] == max({0: -1.0, 1: 0.5}[s] for s in slots)


def test_mesh_edges_and_edges_in():
    v, f = meshgen.grid(3, 2)
    edges = rules.undirected_edges(f)
    brute = sorted({(min(a, b), max(a, b)) for t in f.tolist() for a, b in itertools.combinations(t, 2)})
    assert [tuple(e) for e in edges.tolist()] == brute
    picked = rules.edges_in(edges, [[1, 0], [0, 11], [5, 4]])
    assert [tuple(e) for e in picked.tolist()] == [(0, 1), (4, 5)]


def test_compact_regions():
    a = np.array([5, 5, 7, 7, 9])
    b = np.array([0, 1, 0, 0, 0])
    np.testing.assert_array_equal(rules.compact_regions(a), [0, 0, 1, 1, 2])
    r = rules.compact_regions(a, None, b)
    assert len(set(zip(a.tolist(), b.tolist()))) == len(set(r.tolist()))
    assert all((r[i] == r[j]) == ((a[i], b[i]) == (a[j], b[j])) for i in range(5) for j in range(5))
    assert rules.compact_regions(None) is None
