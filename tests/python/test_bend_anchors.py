"""A sharp bend of a mesh boundary holds its place through the collapses (refine.cpp
add_bend_anchors): border planes are weighted by their edges' squared lengths, so a bend on a rim
of tiny edges held almost nothing and was cut. The mesh: a gyroid cut by a box, a marching-cubes
surface of 563,578 vertices whose rim turns where it crosses an edge of the box, at 0.5 % (a
stochastic first pass, then the collapses). Without the anchors the rim lost a bend at the box's
edge by 1.52 % of the diagonal; with them no rim vertex lies farther than 0.65 % from the result.
Distances by brute force, not by the engine's closest-point search."""

import numpy as np
import pytest

from test_hausdorff import brute_force_distance
from test_large_first_pass import box_cut_gyroid
from test_scan_floor import boundary_edges
from topstoc.core import Mesh

pytest.importorskip("pymeshlab")
pytestmark = pytest.mark.heavy


def test_the_rim_keeps_its_bends_at_the_box_edges():
    vertices, triangles = box_cut_gyroid(0.05)
    assert len(vertices) > 500_000  # a stochastic first pass (first_pass_vertices)
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    diagonal = np.linalg.norm(high - low)
    rim = np.unique(boundary_edges(triangles))
    # Rim vertices near an edge of the box (near two of its faces): where the rim bends.
    near = (np.abs(vertices[rim] - low) < 0.2) | (np.abs(vertices[rim] - high) < 0.2)
    bends = rim[near.sum(axis=1) >= 2]
    assert len(bends) > 50
    result = Mesh(vertices, triangles).decimate(ratio=0.005, seed=0)
    assert result.stats.topology_kept
    distance = brute_force_distance(vertices[bends], result.vertices, result.triangles)
    assert distance.max() <= 0.01 * diagonal, distance.max() / diagonal
