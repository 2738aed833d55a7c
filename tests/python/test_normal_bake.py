"""The figures of a normal-map bake (core/carry/normal_bake.py): ray reach, island gaps, memory, and
the overlap test that decides whether a LOD's UV map can hold a normal map."""

import numpy as np
import pytest

from topstoc.core.carry import normal_bake
from topstoc.core.support.errors import TopStocError


def grid(n, low=0.0, high=1.0):
    """Two triangles per cell of an n x n grid over [low, high]² (no overlap)."""
    g = np.linspace(low, high, n + 1)
    cells = [((g[i], g[j]), (g[i + 1], g[j]), (g[i + 1], g[j + 1]), (g[i], g[j + 1]))
             for i in range(n) for j in range(n)]
    return np.array([tri for a, b, c, d in cells for tri in ((a, b, c), (a, c, d))])


def test_reach_covers_the_distance_both_ways():
    extrusion, ray = normal_bake.ray_reach(0.1, 10.0)
    assert extrusion == pytest.approx(1.25 * 0.1 + 1e-4 * 10.0)
    assert ray == pytest.approx(2 * extrusion)      # from extrusion outside to extrusion inside
    assert normal_bake.ray_reach(0.0, 2.0)[0] > 0  # coincident surfaces still get a ray
    with pytest.raises(TopStocError, match="not a finite number"):
        normal_bake.ray_reach(float("nan"), 1.0)


def test_sizes_and_memory():
    assert normal_bake.check_size(1024) == 1024
    for bad in (8, 20000, 512.0, True, "512"):
        with pytest.raises(TopStocError, match="from 16 to 16384"):
            normal_bake.check_size(bad)
    normal_bake.check_memory(4096, 4096 * 4096 * 16 * 2)  # exactly half the free memory: allowed
    with pytest.raises(TopStocError, match=r"a 8192x8192 normal map needs 1,024 MiB while baking; only "
                                           r"1,024 MiB of memory are free"):
        normal_bake.check_memory(8192, 2**30)
    normal_bake.check_memory(16384, None)                 # unknown memory: not refused


def test_island_margin_is_twice_the_bleed():
    assert normal_bake.island_margin(8, 512) == pytest.approx(16 / 512)
    assert normal_bake.island_margin(0, 512) == 0.0
    assert normal_bake.island_margin(10_000, 16) == 0.5


def test_overlap_fraction():
    tiles = grid(16)
    assert normal_bake.overlap_fraction(tiles) == 0.0            # shared edges are not overlaps
    half = grid(8, 0.0, 0.5)
    mirrored = np.concatenate([half, half[:, ::-1]])              # both halves of a mirrored model
    assert normal_bake.overlap_fraction(mirrored) == pytest.approx(1.0)
    quarter = np.concatenate([grid(4, 0.5, 1.0), grid(4, 0.0, 0.5), grid(2, 0.0, 0.25)])
    # a quarter of the lower-left square (1/16 of the texels covered twice) out of 1/2 covered
    assert normal_bake.overlap_fraction(quarter, 256) == pytest.approx((1 / 16) / (1 / 2), rel=0.02)
    assert normal_bake.overlap_fraction(grid(2, 0.5, 1.5)) == 1.0  # tiles beyond the unit square
    assert normal_bake.overlap_fraction(np.zeros((0, 3, 2))) == 0.0


def test_rasterize_gives_each_texel_centre_its_triangle_and_weights():
    size = 32
    triangles = grid(4)
    texels, triangle, weights = normal_bake.rasterize(triangles, size)
    assert np.allclose(weights.sum(axis=1), 1.0) and (weights >= 0).all()
    centres = np.stack([(texels % size + 0.5) / size, (texels // size + 0.5) / size], axis=1)
    assert np.allclose(np.einsum("ij,ijk->ik", weights, triangles[triangle]), centres)
    assert len(np.unique(texels)) == size * size  # every texel centre, those on the diagonals too
    strict = normal_bake.rasterize(triangles, size, edges=False)[0]
    assert len(strict) == len(np.unique(strict)) < size * size  # on an edge: in neither triangle


def test_dilate_grows_a_texel_by_one_ring_per_step():
    values = np.zeros((9, 9, 3))
    filled = np.zeros((9, 9), dtype=bool)
    values[4, 4], filled[4, 4] = (1.0, 2.0, 3.0), True
    normal_bake.dilate(values, filled, 2)
    distance = np.abs(np.arange(9)[:, None] - 4) + np.abs(np.arange(9)[None, :] - 4)
    assert np.array_equal(filled, distance <= 2)
    assert np.allclose(values[filled], (1.0, 2.0, 3.0)) and not values[~filled].any()
    corner = np.zeros((3, 3, 1))
    reached = np.zeros((3, 3), dtype=bool)
    corner[0, 0], reached[0, 0] = 1.0, True
    normal_bake.dilate(corner, reached, 1)
    assert not reached[2, 0] and not reached[0, 2]  # nothing wraps round the image's edges
