"""A mesh boundary after a stochastic first pass (above 250,000 vertices): the draw keeps every
border vertex and the collapses thin the borders in cost order (sampling.cpp force_curves), and
each border edge holds its triangle's plane weighted by its length times the output's spacing
(refine.cpp add_border_planes), so a rim's profile costs what the surface does. The mesh: a
fractal terrain of 263,169 vertices, whose rim is its profile cut by a box. Drawn at random, the
rim kept vertices many edges apart across valleys; held by the border planes alone (which hold
a rim lying in one plane by nothing across it), the collapses cut its knees. Every input rim
vertex's distance from the result, by brute force: at 10 % at most 0.060 % of the diagonal
before, 0.022 % now; at 2 % 0.28 % before, 0.11 % now."""

import numpy as np
import pytest

from test_hausdorff import brute_force_distance
from test_large_first_pass import fractal_terrain
from test_scan_floor import boundary_edges
from topstoc.core import Mesh

pytest.importorskip("pymeshlab")
pytestmark = pytest.mark.heavy


def rim_distance(vertices, triangles, result):
    """The largest distance of an input rim vertex from the result, over its diagonal: the
    result's triangles within 2 % of the box's sides searched (the rim lies on them)."""
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    band = 0.02 * (high - low)[:2]
    near = ((np.abs(result.vertices[:, :2] - low[:2]) < band) | (np.abs(result.vertices[:, :2] - high[:2]) < band)).any(axis=1)
    around = result.triangles[near[result.triangles].any(axis=1)]
    rim = np.unique(boundary_edges(triangles))
    return brute_force_distance(vertices[rim], result.vertices, around).max() / np.linalg.norm(high - low)


@pytest.mark.parametrize("share, most", [(10, 0.00035), (50, 0.0017)], ids=["10 %", "2 %"])
def test_a_terrains_rim_keeps_its_profile(share, most):
    vertices, triangles = fractal_terrain()
    assert len(vertices) > 250_000  # a stochastic first pass (first_pass_vertices)
    result = Mesh(vertices, triangles).decimate(target_triangles=len(triangles) // share, seed=0)
    assert result.stats.topology_kept
    assert result.stats.selected < len(vertices)
    assert rim_distance(vertices, triangles, result) <= most
