"""A flat strip of needles (a grid of cells a thousand times longer than wide): every triangle is
a sliver, so the collapses may leave triangles as thin as the input's own (not only as the
thinnest around them), and the strip's corners stay. Checked with numpy, independently of the
engine: the result lies in the strip's plane, faces up everywhere, covers the strip's area and
keeps its ends; it is a disk.
"""

import numpy as np
import pytest

import meshgen
import reference
from topstoc.core import Mesh


def strip(cells: int, rows: int, width: float = 0.001):
    v, t = meshgen.grid(cells, rows)
    v = np.asarray(v, dtype=np.float64).copy()
    v[:, 1] *= width
    return v, np.asarray(t, dtype=np.int32)


def twice_areas(vertices, triangles):
    """Signed twice-areas of the triangles in the xy plane (positive: facing +z)."""
    p = np.asarray(vertices)[np.asarray(triangles)]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def assert_covers_the_strip(v, t, r):
    out_v, out_t = np.asarray(r.vertices), np.asarray(r.triangles)
    assert np.all(out_v[:, 2] == 0.0)
    np.testing.assert_array_equal(out_v.min(0), v.min(0))  # the ends stay
    np.testing.assert_array_equal(out_v.max(0), v.max(0))
    areas = twice_areas(out_v, out_t)
    assert np.all(areas > 0)  # no flip: with the same total area the strip is covered once
    assert areas.sum() == pytest.approx(twice_areas(v, t).sum(), rel=1e-9)
    assert reference.invariants(len(out_v), out_t) == reference.invariants(len(v), t)


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_a_needle_strip_reaches_its_target_flat_and_whole(mode):
    v, t = strip(7000, 8)
    target = len(t) // 10
    r = Mesh(v, t).decimate(target_triangles=target, seed=0, mode=mode)
    assert abs(len(r.triangles) - target) <= 0.01 * target
    assert r.stats.target_missed is None and not r.stats.shape_floor
    assert_covers_the_strip(v, t, r)


@pytest.mark.parametrize("mode", ["quality", "fast"])
@pytest.mark.parametrize("cells, rows, width", [(5000, 2, 0.001), (2000, 4, 0.05)])
def test_a_strip_too_thin_for_its_target_keeps_its_ends_and_says_why(mode, cells, rows, width):
    # 2 % needs triangles thinner than the input's: the result stops above the target instead
    # of eating the strip from its ends (main's 2,000 x 4 strip at 2 %: 25 % of the diagonal off)
    v, t = strip(cells, rows, width)
    r = Mesh(v, t).decimate(target_triangles=len(t) // 50, seed=0, mode=mode)
    assert len(r.triangles) < len(t) // 3
    assert_covers_the_strip(v, t, r)
    assert r.stats.shape_floor
    missed = r.stats.target_missed
    assert missed.reason == "needle triangles"
    assert "no thinner than the input's own needles" in missed.detail


def test_needles_are_the_reason_before_topology_and_borders():
    from types import SimpleNamespace

    from topstoc.core.api.budget import over_reason

    base = dict(forced=0, target_vertices=500, control_points=0, mirrored_from=0, nonmanifold_vertices=0,
                output_vertices=900)
    assert over_reason(SimpleNamespace(**base, shape_floor=True)) == "needle triangles"
    assert over_reason(SimpleNamespace(**{**base, "forced": 600}, shape_floor=True)) == "needle triangles"
    assert over_reason(SimpleNamespace(**base)) == "topology"
