"""Fast mode at tiny budgets on a CAD part (open_manipulator's link1: 21,376 triangles, 58 % of
them slivers, genus 0). Fast mode keeps input positions, so near the target the shape rule left
few collapses, and only costly ones: on some copies the last dozen collapses crushed the part
(main: 10 of 30 copies jittered by a millionth of a millimetre, down to no volume at all). The
tail now runs twice, the second under looser shape limits, and the measured deviation chooses
(refine.cpp tail_choice). Checked with numpy, independently of the engine: the signed volume,
the topology, and every output vertex an input vertex. The copies are jittered because which
copy crushed on main depends on ties between the part's exactly coplanar faces.
"""

import pathlib

import numpy as np
import pytest

import reference
from topstoc.core import Mesh, read_mesh

LINK = pathlib.Path(__file__).resolve().parents[1] / "data" / "cad" / "open_manipulator_x_link1.stl.gz"
TARGETS = (100, 150, 180, 214, 250)


def volume(vertices, triangles):
    p = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles)]
    return np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6.0


@pytest.fixture(scope="module")
def link():
    data = read_mesh(LINK)
    return np.asarray(data.vertices, dtype=np.float64), np.asarray(data.triangles)


def jittered(link, seed):
    vertices, triangles = link
    return vertices + np.random.default_rng(seed).uniform(-1e-6, 1e-6, vertices.shape), triangles


@pytest.mark.parametrize("seed", range(10))
def test_fast_mode_keeps_a_cad_parts_volume_at_tiny_budgets(link, seed):
    vertices, triangles = jittered(link, seed)
    mesh, whole = Mesh(vertices, triangles), volume(vertices, triangles)
    for target in TARGETS:
        r = mesh.decimate(target_triangles=target, seed=0, mode="fast")
        assert r.num_triangles == target
        assert volume(r.vertices, r.triangles) / whole == pytest.approx(1.0, abs=0.05), target
        assert reference.invariants(r.num_vertices, r.triangles) == reference.invariants(len(vertices), triangles)
        kept = {tuple(p) for p in vertices}
        assert all(tuple(p) in kept for p in np.asarray(r.vertices))


def test_fast_mode_on_a_copy_main_crushed_is_as_near_as_meshlab(link, tmp_path):
    """Seed 4 at 180 triangles, by MeshLab's own Hausdorff (% of the diagonal): main's result
    had no volume left, max 51.4 and mean 14.3 against MeshLab's quadric collapse's 4.2 and 0.35
    at the same count; now 3.0 and 0.27 (MeshLab places optimally, fast mode keeps input
    positions)."""
    pytest.importorskip("pymeshlab")
    from test_large_first_pass import ours_and_meshlabs

    vertices, triangles = jittered(link, 4)
    ours = Mesh(vertices, triangles).decimate(target_triangles=180, seed=0, mode="fast")
    (our_max, our_mean), (their_max, their_mean) = ours_and_meshlabs(tmp_path, vertices, triangles, ours)
    assert our_mean <= their_mean, (our_mean, their_mean)
    assert our_max <= 1.25 * their_max, (our_max, their_max)
