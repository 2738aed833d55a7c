"""No zero-area triangle in an output where the topology allows one without (issue 16, item 5).

Measured before the fixes: the genus-133 hole grid left a triangle of three collinear input
vertices at 5 % in fast mode (no collapse is allowed there: every vertex carries a hole), and
the spider kept all 56 zero-area triangles of its input (fans of coincident vertices) in
quality mode, 6-20 in fast mode. Zero area is measured here in the output's own coordinates.
"""

import pathlib

import numpy as np
import pytest

import meshgen
from topstoc.core import Mesh, read_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


def zero_area(result) -> int:
    p = result.vertices[result.triangles]
    return int(np.count_nonzero(np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1) == 0))


@pytest.mark.parametrize("mode", ["fast", "quality"])
@pytest.mark.heavy
def test_collinear_vertices_of_a_genus_133_grid(mode):
    mesh = Mesh(*meshgen.genus_grid(7, 19, scale=(2, 2, 3)))
    for ratio in (0.05, 0.03):
        for seed in range(4):
            r = mesh.decimate(ratio=ratio, seed=seed, mode=mode)
            assert r.stats.topology_kept
            assert zero_area(r) == 0 == r.stats.issues_remaining["sliver"], (ratio, seed)
            if mode == "fast":  # the fix moves a corner to another input vertex of its cluster
                np.testing.assert_array_equal(r.vertices, mesh.vertices[r.kept])


def test_coincident_vertices_of_the_spider():
    data = read_mesh(DATA / "uv_materials/spider/spider.obj")
    mesh = Mesh(data.vertices, data.triangles)
    assert mesh.report().zero_area_triangles == 56
    for ratio in (0.2, 0.05, 0.02):
        for seed in range(3):
            quality = mesh.decimate(ratio=ratio, seed=seed)
            assert zero_area(quality) == 0 == quality.stats.issues_remaining["sliver"], (ratio, seed)
            fast = mesh.decimate(ratio=ratio, seed=seed, mode="fast")
            # fast mode keeps input positions: a component reduced to a tetrahedron of
            # coincident input vertices has no other choice (reported)
            assert zero_area(fast) == fast.stats.issues_remaining["sliver"] <= 4, (ratio, seed)
