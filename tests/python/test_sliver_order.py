"""Quality mode takes the slivers out before its error-ordered collapses (refine.cpp
slivers_first), each by the first of its six directed collapses that passes the checks, those
that move a vertex off every border tried first (Collapser::remove_thin). Taken in corner order,
a sliver at a rim's bend moved the bend's vertex along the sliver's long edge: on a box-cut
gyroid the rim lost that corner by 0.29 % of the whole mesh's diagonal at 50 % of the vertices,
where every other rim vertex stayed within 0.02 %. The mesh here is the part of that gyroid
around the corner (tests/data/open_boundary/gyroid_rim_corner.npz; tests/data/LICENSES.md); the
distances are measured by brute force, not by the engine's closest-point search."""

import pathlib

import numpy as np
import pytest

from test_hausdorff import brute_force_distance
from test_scan_floor import boundary_edges
from topstoc.core import Mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data" / "open_boundary" / "gyroid_rim_corner.npz"


@pytest.mark.parametrize("ratio", [0.9, 0.5, 0.2])
def test_the_rim_keeps_its_corner(ratio):
    data = np.load(DATA)
    vertices, triangles, corner = data["vertices"], data["triangles"], int(data["corner"])
    diagonal = np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0))
    rim = np.unique(boundary_edges(triangles))
    assert corner in rim
    result = Mesh(vertices, triangles).decimate(ratio=ratio, seed=0)
    assert result.stats.topology_kept
    # Corner order cut it by 1.5-2.3 % of this patch's diagonal; now 0.001-0.021 %.
    distance = brute_force_distance(vertices[[corner]], result.vertices, result.triangles)[0]
    assert distance <= 1e-3 * diagonal, distance / diagonal
    # Nor does any other rim vertex go far (0.11-0.40 %): the rim is decimated along itself.
    rim_distance = brute_force_distance(vertices[rim], result.vertices, result.triangles)
    assert rim_distance.max() <= 6e-3 * diagonal, rim_distance.max() / diagonal
