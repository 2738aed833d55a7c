"""Quality mode on meshes of more than 80,000 vertices against MeshLab's quadric collapse
(docs/bench_notes/large-first-pass.md), both results measured by MeshLab's Hausdorff filter,
MeshLab decimating to our triangle count:
- a gyroid cut by a box, a marching-cubes surface of about 115,000 vertices whose rim turns at
  the box's edges. From a stochastic first pass its max error at 10 % was 6.3 times MeshLab's;
  collapsed whole it is 1.19 times (the goal of issue 40, 1.15, is not met here);
- a fractal terrain of 263,169 vertices (above the whole-mesh limit) at 2 %: from a first pass
  of 8 times the target (42,000 vertices) its max error was 0.81 times MeshLab's; from one of
  125,000 (first_pass_vertices' floor) 0.69 times;
- the CGAL Chinese dragon Loop-subdivided three times (639,832 vertices, above the floor's end,
  smooth as the subdivided horse is) at 10 %: from a first pass of the target and a quarter
  more its mean error was 1.95 times MeshLab's and its max 3.13 times; from one of
  min(8 x target, 250,000), 1.03 and 0.99 times."""

import math
import pathlib

import pytest

from peer_runs import meshlab_hausdorff, write_off
from topstoc.core import Mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"

pymeshlab = pytest.importorskip("pymeshlab")
pytestmark = pytest.mark.heavy


def arrays(ms):
    """The current mesh of a pymeshlab MeshSet as (vertices, triangles)."""
    m = ms.current_mesh()
    return m.vertex_matrix(), m.face_matrix()


def box_cut_gyroid(voxel=0.11):
    ms = pymeshlab.MeshSet()
    ms.create_implicit_surface(expr="sin(x)*cos(y)+sin(y)*cos(z)+sin(z)*cos(x)", voxelsize=voxel,
                               minx=-6.2, miny=-6.2, minz=-6.2, maxx=6.2, maxy=6.2, maxz=6.2)
    ms.meshing_merge_close_vertices()
    ms.meshing_remove_unreferenced_vertices()
    return arrays(ms)


def meshlab_decimation(vertices, triangles, target_triangles):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertices, triangles))
    ms.meshing_decimation_quadric_edge_collapse(targetfacenum=target_triangles, optimalplacement=True,
                                                preservetopology=True, preserveboundary=True)
    return arrays(ms)


def symmetric(distances):
    return max(distances["forward"]["max"], distances["backward"]["max"]), \
        (distances["forward"]["mean"] + distances["backward"]["mean"]) / 2


def ours_and_meshlabs(tmp_path, vertices, triangles, ours):
    """(max, mean) of our result and of MeshLab's at our triangle count, by MeshLab's Hausdorff."""
    theirs = meshlab_decimation(vertices, triangles, ours.num_triangles)
    paths = {name: tmp_path / f"{name}.off" for name in ("input", "ours", "theirs")}
    write_off(paths["input"], vertices, triangles)
    write_off(paths["ours"], ours.vertices, ours.triangles)
    write_off(paths["theirs"], *theirs)
    return [symmetric(meshlab_hausdorff(paths["input"], paths[name], samples=300_000)) for name in ("ours", "theirs")]


def test_a_box_cut_gyroid_at_ten_percent_stays_near_meshlab(tmp_path):
    vertices, triangles = box_cut_gyroid()
    assert 80_000 < len(vertices) < 250_000  # above the old limit of a whole-mesh start
    ours = Mesh(vertices, triangles).decimate(target_triangles=len(triangles) // 10, seed=0)
    (our_max, our_mean), (their_max, their_mean) = ours_and_meshlabs(tmp_path, vertices, triangles, ours)
    assert ours.stats.topology_kept
    assert our_max <= 1.25 * their_max, (our_max, their_max)
    assert our_mean <= 1.05 * their_mean, (our_mean, their_mean)


def fractal_terrain():
    ms = pymeshlab.MeshSet()
    ms.create_fractal_terrain(steps=9, seed=2)
    return arrays(ms)


def subdivided_chinese_dragon():
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(DATA / "genus0" / "cgal_ChineseDragon-10kv.off"))
    ms.meshing_surface_subdivision_loop(iterations=3, threshold=pymeshlab.PercentageValue(0))
    return arrays(ms)


# Above the whole-mesh limit: (mesh, its vertex range, 1 / the target's share of the triangles,
# the first pass, at most our max and mean over MeshLab's).
ABOVE_THE_LIMIT = [
    # Up to the floor's end: the floor of 125,000, not 8 x the target (42,000).
    (fractal_terrain, (250_000, 500_000), 50, 125_000, 0.75, 0.85),
    # Above it: min(8 x the target, 250,000), not the target and a quarter (80,000).
    (subdivided_chinese_dragon, (500_000, math.inf), 10, 250_000, 1.15, 1.10),
]


@pytest.mark.parametrize("make, sizes, share, selected, max_factor, mean_factor", ABOVE_THE_LIMIT,
                         ids=["terrain at 2 %", "subdivided dragon at 10 %"])
def test_a_mesh_above_the_whole_mesh_limit_starts_from_its_floor(tmp_path, make, sizes, share, selected,
                                                                 max_factor, mean_factor):
    vertices, triangles = make()
    assert sizes[0] < len(vertices) <= sizes[1]
    ours = Mesh(vertices, triangles).decimate(target_triangles=len(triangles) // share, seed=0)
    assert ours.stats.selected == selected
    (our_max, our_mean), (their_max, their_mean) = ours_and_meshlabs(tmp_path, vertices, triangles, ours)
    assert ours.stats.topology_kept
    assert our_max <= max_factor * their_max, (our_max, their_max)
    assert our_mean <= mean_factor * their_mean, (our_mean, their_mean)
