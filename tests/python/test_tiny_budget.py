"""Tiny budgets: a quality result of at most 1,400 triangles is fitted to the input by least
squares both ways (four rounds up to 400 triangles, moving mesh boundaries too; one above,
boundaries kept) (native/src/decimate/tiny_fit.cpp, docs/design.md §2.10).

Errors are measured by topstoc.hausdorff (checked against CGAL in test_hausdorff_peers.py) and
compared with meshoptimizer's quadric simplification at the same triangle count; the boundary
check measures the result's boundary against the input's boundary polyline in numpy.
"""

import json
import pathlib

import numpy as np
import pytest

import topstoc
from peer_runs import cgal_hausdorff, meshopt_simplify, peer, read_off, write_off
from reference import invariants


def _boundary_edges(triangles):
    t = np.asarray(triangles)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    return unique[count == 1]


def _distance_to_segments(points, a, b):
    """Distance from each point to the nearest of the segments a[i]-b[i]."""
    d = b - a
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.einsum("pij,ij->pi", points[:, None, :] - a[None], d) / np.where(length2 > 0, length2, 1.0)[None]
    closest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * d[None]
    return np.sqrt(((points[:, None, :] - closest) ** 2).sum(axis=2)).min(axis=1)


@pytest.mark.parametrize("name, target", [("genus0/cgal_fandisk.off", 25), ("open_boundary/cgal_mushroom.off", 50)])
def test_tiny_budget_beats_meshopt_mean_and_max(data_dir, tmp_path, name, target):
    if peer("meshopt_simplify") is None:
        pytest.skip("peer program meshopt_simplify was not built (libmeshoptimizer-dev)")
    source = data_dir / name
    vertices, triangles = read_off(source)
    ours = topstoc.Mesh(vertices, triangles).decimate(target_triangles=target, seed=0)
    assert abs(len(ours.triangles) - target) <= 1
    assert ours.stats.topology_kept
    assert invariants(len(ours.vertices), ours.triangles) == invariants(len(vertices), triangles)
    theirs_path = tmp_path / "meshopt.off"
    meshopt_simplify(source, theirs_path, 3 * len(ours.triangles))
    theirs = read_off(theirs_path)
    assert len(theirs[1]) <= len(ours.triangles)
    ours_error = topstoc.hausdorff((vertices, triangles), (ours.vertices, ours.triangles), samples=200_000)
    theirs_error = topstoc.hausdorff((vertices, triangles), theirs, samples=200_000)
    # without the tiny-budget fit fandisk at 25 triangles loses to meshopt on both (design.md §2.10)
    assert ours_error.symmetric.mean < 0.95 * theirs_error.symmetric.mean
    assert ours_error.symmetric.max < theirs_error.symmetric.max


@pytest.mark.parametrize("target", [25, 50, 100])
def test_tiny_fit_keeps_boundaries_near_the_input_boundary(data_dir, target):
    # The fit moves boundary vertices too (a mesh boundary has one side, nothing to keep exact
    # across it): the result's boundary must stay as near the input's boundary polyline as the
    # surface stays near the input, and keep its loops.
    vertices, triangles = read_off(data_dir / "open_boundary/cgal_mushroom.off")
    vertices = np.asarray(vertices, dtype=float)
    result = topstoc.Mesh(vertices, triangles).decimate(target_triangles=target, seed=0)
    assert result.stats.topology_kept
    assert invariants(len(result.vertices), result.triangles) == invariants(len(vertices), triangles)
    source_edges, result_edges = _boundary_edges(triangles), _boundary_edges(result.triangles)
    out = np.asarray(result.vertices, dtype=float)
    s = np.linspace(0.0, 1.0, 9)[None, :, None]
    points = (out[result_edges[:, 0]][:, None] * (1 - s) + out[result_edges[:, 1]][:, None] * s).reshape(-1, 3)
    boundary = _distance_to_segments(points, vertices[source_edges[:, 0]], vertices[source_edges[:, 1]]).max()
    surface = topstoc.hausdorff((vertices, triangles), (result.vertices, result.triangles), samples=100_000)
    assert boundary <= surface.symmetric.max
    zero = np.linalg.norm(np.cross(out[result.triangles[:, 1]] - out[result.triangles[:, 0]],
                                   out[result.triangles[:, 2]] - out[result.triangles[:, 0]]), axis=1) == 0
    assert not zero.any()


# Small results whose max the fit used to raise (it judged the max on its own samples only), with
# the best peer's max on the same case: Blender Collapse at our triangle count, in % of the
# diagonal, from docs/bench_results/bench_quality_worst_cases_after.json (bench_quality.py, 100k
# samples: a lower bound of Blender's true max). (mesh, target, bound on ours over Blender's.)
# The old fit gave 1.38 (knot1) and 1.80 (mushroom); mushroom was 1.15 until the fit took the
# vertex at its far point halfway back (tiny_fit.cpp, back_off): 1.06, then 1.11 with the border
# span costs (which lowered most bordered results' max: docs/bench_notes/outline-spans.md). Both
# are held to issue 40's goal, 1.15 times the best peer.
WORST_SMALL = [("genus_positive/cgal_knot1.off", 128, 1.15), ("open_boundary/cgal_mushroom.off", 92, 1.15)]
BENCH = pathlib.Path(__file__).resolve().parents[2] / "docs/bench_results/bench_quality_worst_cases_after.json"


@pytest.mark.parametrize("name, target, bound", WORST_SMALL, ids=[w[0] for w in WORST_SMALL])
def test_the_fit_keeps_the_max_near_the_best_peer(data_dir, tmp_path, name, target, bound):
    if peer("cgal_hausdorff") is None:
        pytest.skip("peer program cgal_hausdorff was not built (CGAL)")
    case = next(c for c in json.loads(BENCH.read_text())["cases"]
                if c["mesh"] == pathlib.Path(name).name and c["target"] == target)
    blender = case["tools"]["Blender Collapse"]
    vertices, triangles = read_off(data_dir / name)
    ours = topstoc.Mesh(vertices, triangles).decimate(target_triangles=target, seed=0)
    # no more triangles than the peer had (the max-aware choice may stop one below the target)
    assert len(ours.triangles) <= blender["triangles"] and ours.stats.topology_kept
    write_off(tmp_path / "in.off", vertices, triangles)
    write_off(tmp_path / "ours.off", ours.vertices, ours.triangles)
    # CGAL's bounded max both ways (independent of the engine's distance code), in % of the diagonal
    cgal = cgal_hausdorff(tmp_path / "in.off", tmp_path / "ours.off", mean_samples=10_000)
    v = np.asarray(vertices, dtype=float)
    ours_max = 100 * max(cgal["forward"]["max_bounded"], cgal["backward"]["max_bounded"]) / np.linalg.norm(
        v.max(axis=0) - v.min(axis=0))
    assert ours_max <= bound * blender["max"], ours_max / blender["max"]


# Worst cases of the broad benchmark that the fit now reaches (results of 401-1,400 triangles,
# one round, mesh boundaries kept): the peers' figures are bench_quality.py's (100k samples, in % of the diagonal) for
# the same case at our triangle count, from docs/bench_results/bench_quality_broad_fit_max_check.json:
# fast-simplification (PyPI), MeshLab's and Blender's quadric collapses. Ours is measured the same
# way (topstoc.hausdorff, 100k samples, checked against CGAL in test_hausdorff_peers.py).
# (mesh, ratio, peer, bound on our mean over the peer's, bound on our max over the peer's or None).
# Without the fit: the elephant 0.92 (mean) and 0.83 (max) of Blender's, the duck 0.91 of
# MeshLab's mean, knot1 0.97 of Blender's mean.
WORST_MIDDLE = [("genus_positive/cgal_elephant.off", 0.1, "Blender Collapse", 0.86, 0.8),
                ("uv_materials/duck/duck_via_assimp.obj", 0.1, "MeshLab", 0.8, None),
                ("genus_positive/cgal_knot1.off", 0.1, "Blender Collapse", 0.88, None)]
BROAD = pathlib.Path(__file__).resolve().parents[2] / "docs/bench_results/bench_quality_broad_fit_max_check.json"


@pytest.mark.parametrize("name, ratio, peer_name, mean_bound, max_bound", WORST_MIDDLE, ids=[w[0] for w in WORST_MIDDLE])
def test_the_fit_of_a_middle_result_beats_the_peer_it_lost_to(data_dir, name, ratio, peer_name, mean_bound, max_bound):
    case = next(c for c in json.loads(BROAD.read_text())["cases"]
                if c["mesh"] == pathlib.Path(name).name and c["ratio"] == ratio)
    theirs = case["tools"][peer_name]
    source = topstoc.read_mesh(data_dir / name)
    vertices, triangles = source.vertices, source.triangles
    ours = topstoc.Mesh(vertices, triangles).decimate(target_triangles=case["target"], seed=0)
    assert 400 < len(ours.triangles) <= 1400 and abs(len(ours.triangles) - theirs["triangles"]) <= 5
    assert ours.stats.topology_kept
    assert invariants(len(ours.vertices), ours.triangles) == invariants(len(vertices), triangles)
    error = topstoc.hausdorff((vertices, triangles), (ours.vertices, ours.triangles), samples=100_000,
                              relative=True, percentile=0)
    assert 100 * error.symmetric.mean <= mean_bound * theirs["mean"], 100 * error.symmetric.mean / theirs["mean"]
    if max_bound is not None:
        assert 100 * error.symmetric.max <= max_bound * theirs["max"], 100 * error.symmetric.max / theirs["max"]
