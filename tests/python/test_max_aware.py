"""Quality mode on a mesh it collapses whole: the first pass keeps every vertex up to
8 x QUALITY_COLLAPSES vertices, and the last collapses are rerun from twice the target, weighted
by where the runs before ended farthest from the input (refine.cpp, collapse_max_aware).

Errors by topstoc.hausdorff (checked against a brute-force distance in test_hausdorff.py);
topology, orientation and degeneracy by tests/reference.py, independent of the engine; the
worst cases against meshoptimizer's simplifier (build/peers/meshopt_simplify), run here.
"""

import pathlib

import numpy as np
import pytest

import meshgen
import reference
from peer_runs import meshopt_simplify, peer, write_off
from test_decimate import check_output
from topstoc.core import Mesh, hausdorff, read_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


def bumpy_torus():
    """A 60,000-vertex torus with a ripple: above the old whole-mesh limit (50,000), below the new."""
    v, t = meshgen.torus(nu=300, nv=200)
    around = np.arctan2(v[:, 1], v[:, 0])
    across = np.arctan2(v[:, 2], np.hypot(v[:, 0], v[:, 1]) - 1.0)
    return v * (1.0 + 0.03 * np.sin(7 * around) * np.cos(5 * across))[:, None], t


@pytest.mark.heavy
def test_a_mesh_of_60k_vertices_is_collapsed_whole():
    v, t = bumpy_torus()
    mesh = Mesh(v, t)
    r = mesh.decimate(ratio=0.02, seed=0)
    # Every removed vertex went by a collapse: the first pass kept them all. With the whole-mesh
    # limit at 50,000 the stochastic pass kept 11,200 and the collapses removed 10,000.
    assert r.stats.refine_collapses == mesh.num_vertices - r.num_vertices
    check_output(mesh, r, reference.invariants(len(v), t))
    # measured: max 0.00177 of the diagonal with the stochastic first pass, 0.00140 now
    assert hausdorff((v, t), r, samples=100_000, relative=True).symmetric.max < 0.0016


# (mesh, ratio, the max error of one run of collapses, the bound now, the mean now at most):
# measured with 100,000 samples: elephant max 0.0138 -> 0.0106 (mean 0.00142 -> 0.00146),
# Chinese dragon 0.0099 -> 0.0079 (mean 0.00098 -> 0.00102).
HARDEST = [("genus_positive/cgal_elephant.off", 0.1, 0.0138, 0.0120, 0.00155),
           ("genus0/cgal_ChineseDragon-10kv.off", 0.1, 0.0099, 0.0090, 0.00108)]


@pytest.mark.parametrize("name, ratio, before, bound, mean_bound", HARDEST, ids=[h[0] for h in HARDEST])
def test_the_second_run_lowers_the_max_error(name, ratio, before, bound, mean_bound):
    v, t = reference.read_off(DATA / name)
    mesh = Mesh(v, t)
    r = mesh.decimate(ratio=ratio, seed=0)
    error = hausdorff((v, t), r, samples=100_000, relative=True).symmetric
    assert error.max < bound < before, (name, error.max)
    assert error.mean < mean_bound, (name, error.mean)  # the mean pays a few percent at most
    check_output(mesh, r, reference.invariants(len(v), t))


def test_the_second_run_is_deterministic():
    v, t = reference.read_off(DATA / "genus_positive/cgal_elephant.off")
    mesh = Mesh(v, t)
    a, b = mesh.decimate(ratio=0.05, seed=3), mesh.decimate(ratio=0.05, seed=3)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.triangles, b.triangles)


ADVERSARIAL = [
    ("pinched sphere", meshgen.pinched_sphere(2)),
    ("theta surface", meshgen.theta_surface(12)),
    ("book", meshgen.book(4)),
    ("Moebius strip", meshgen.mobius(24, 3)),
    ("two tori", meshgen.disjoint(meshgen.torus(24, 12), meshgen.torus(16, 10, major=3.0))),
]


@pytest.mark.parametrize("what, mesh", ADVERSARIAL, ids=[a[0] for a in ADVERSARIAL])
def test_guarantees_hold_on_adversarial_inputs(what, mesh):
    v, t = mesh
    expected = reference.invariants(len(v), t)
    m = Mesh(v, t)
    for ratio in (0.3, 0.1):
        r = m.decimate(ratio=ratio, seed=0)
        assert reference.invariants(r.num_vertices, r.triangles) == expected, (what, ratio)
        assert reference.degenerate_or_duplicate(r.triangles) == (0, 0), (what, ratio)
        assert not any(r.stats.output_check.values()), (what, ratio, r.stats.output_check)


# The cases of tests/data where the max error is furthest above meshoptimizer's at the same
# triangle count (bench_quality.py, issue 40): (mesh, ratio, bound on ours / meshopt's, the
# ratio with one rerun from scratch). Ours is the guaranteed bound (max_upper), meshopt's the
# largest distance found, a lower bound of its max: the ratio of the true maxima is below it.
# couplingdown (a CAD part at 2 %) stays above the 1.15 goal.
WORST = [("genus_positive/cgal_couplingdown.off", 0.02, 1.25, 1.206),
         ("genus_positive/cgal_elephant.off", 0.02, 1.06, 1.082),
         ("genus_positive/cgal_anchor_dense.off", 0.02, 1.06, 1.028),
         ("genus_positive/cgal_turbine.off", 0.02, 0.90, 0.936)]


@pytest.mark.parametrize("name, ratio, bound, before", WORST, ids=[w[0] for w in WORST])
def test_the_max_error_against_meshopt_on_the_worst_cases(tmp_path, name, ratio, bound, before):
    if peer("meshopt_simplify") is None:
        pytest.skip("peer program meshopt_simplify was not built (libmeshoptimizer-dev)")
    v, t = reference.read_off(DATA / name)
    r = Mesh(v, t).decimate(target_triangles=round(ratio * len(t)), seed=0)
    write_off(tmp_path / "in.off", v, t)
    meshopt_simplify(tmp_path / "in.off", tmp_path / "meshopt.off", 3 * r.num_triangles)
    theirs = read_mesh(str(tmp_path / "meshopt.off"))
    assert theirs.num_triangles <= r.num_triangles  # the peer has no more triangles than we do
    ours = hausdorff((v, t), r, samples=100_000, relative=True).symmetric
    peer_max = hausdorff((v, t), theirs, samples=100_000, relative=True, max_tolerance=0).symmetric.max
    assert ours.max_upper < bound * peer_max, (name, ours.max_upper / peer_max)


# Worst max cases of the broad benchmark whose reruns had found a far smaller max that the choice
# refused (refine.cpp, Refinement::wins): the mushroom's rerun paid 7.5 % of mean for 21 % of max
# (the mean bound was 5 %); polygon_mesh and couplingdown gained with the third rerun (weight 30
# between two at 100) and the rule that a max gain must outweigh the mean's loss. The peer is Blender's Decimate
# (Collapse, keeping the topology) at our triangle count, from bench_quality.py's run in
# docs/bench_results/bench_quality_broad_fit_middle_after.json (100k samples, % of the diagonal);
# ours is measured the same way. (mesh, ratio, bound on our max / Blender's, on our mean / Blender's.)
# Before: mushroom 1.20 (max), polygon_mesh 1.13, couplingdown 1.11; now 0.98, 0.82, 1.03.
BROAD_42 = pathlib.Path(__file__).resolve().parents[2] / "docs/bench_results/bench_quality_broad_fit_middle_after.json"
REFUSED = [("open_boundary/cgal_mushroom.off", 0.1, 1.05, 0.85),
           ("nonmanifold_degenerate/cgal_polygon_mesh.off", 0.1, 0.95, 0.9),
           ("genus_positive/cgal_couplingdown.off", 0.1, 1.06, 0.7)]


@pytest.mark.parametrize("name, ratio, max_bound, mean_bound", REFUSED, ids=[r[0] for r in REFUSED])
def test_the_choice_takes_the_rerun_that_lowers_the_max(name, ratio, max_bound, mean_bound):
    import json
    case = next(c for c in json.loads(BROAD_42.read_text())["cases"]
                if c["mesh"] == pathlib.Path(name).name and c["ratio"] == ratio)
    blender = case["tools"]["Blender Collapse"]
    assert blender["topology"]
    source = read_mesh(str(DATA / name))
    v, t = source.vertices, source.triangles
    mesh = Mesh(v, t)
    r = mesh.decimate(target_triangles=case["target"], seed=0)
    assert abs(r.num_triangles - blender["triangles"]) <= 2
    check_output(mesh, r, reference.invariants(len(v), t))
    error = hausdorff((v, t), r, samples=100_000, relative=True, percentile=0).symmetric
    assert 100 * error.max <= max_bound * blender["max"], 100 * error.max / blender["max"]
    assert 100 * error.mean <= mean_bound * blender["mean"], 100 * error.mean / blender["mean"]


# Below its floor (the topology or the borders stop the collapses above the target) the reruns
# had restarted from twice the target, which the first run never reached: they began at its end
# and could not move a vertex, and the last collapses, forced, folded or bridged the surface. They
# now restart from twice where it ended and stop where it did, under looser shape checks
# (refine.cpp, restart_above, kFloorShape). The peers at our triangle count from bench_quality.py's
# run in docs/bench_results/bench_quality_floor_after.json (100k samples, % of the diagonal); ours
# measured the same way. (mesh, target, peer, bound on our max / its, on our mean / its.)
# Before (bench_quality_floor_before.json): turbine at its genus-11 floor of 138 triangles 1.66
# and 1.53 of MeshLab's (which keeps the topology there too), now 0.73 and 0.69; polygon_mesh at
# 158, 3.75 and 1.49 of Blender's, now 1.02 and 0.91.
FLOOR = pathlib.Path(__file__).resolve().parents[2] / "docs/bench_results/bench_quality_floor_after.json"
BELOW_FLOOR = [("genus_positive/cgal_turbine.off", 50, "MeshLab", 0.85, 0.8),
               ("nonmanifold_degenerate/cgal_polygon_mesh.off", 50, "Blender Collapse", 1.15, 1.0)]


@pytest.mark.parametrize("name, target, peer_name, max_bound, mean_bound", BELOW_FLOOR, ids=[b[0] for b in BELOW_FLOOR])
@pytest.mark.heavy
def test_below_the_floor_the_result_nears_the_peers(name, target, peer_name, max_bound, mean_bound):
    import json
    case = next(c for c in json.loads(FLOOR.read_text())["cases"]
                if c["mesh"] == pathlib.Path(name).name and c["budget"] == target)
    theirs = case["tools"][peer_name]
    source = read_mesh(str(DATA / name))
    v, t = source.vertices, source.triangles
    mesh = Mesh(v, t)
    results = [mesh.decimate(target_triangles=x, seed=0) for x in (target, 2 * target)]
    r = results[0]
    # at most the peers' count (past the floor, a scan's rim may lose a few more: extend_past_floor)
    assert r.stats.over_budget_reason == "topology" and r.num_triangles <= case["peer_triangles"]
    # never compared at more triangles than the peer's (the span costs lowered polygon_mesh's
    # floor from 158 to 153 triangles)
    assert r.num_triangles <= theirs["triangles"] + 2
    check_output(mesh, r, reference.invariants(len(v), t))
    # a target below the floor gives the floor's result whatever it is
    assert np.array_equal(results[1].vertices, r.vertices) and np.array_equal(results[1].triangles, r.triangles)
    error = hausdorff((v, t), r, samples=100_000, relative=True, percentile=0).symmetric
    assert 100 * error.max <= max_bound * theirs["max"], 100 * error.max / theirs["max"]
    assert 100 * error.mean <= mean_bound * theirs["mean"], 100 * error.mean / theirs["mean"]


def test_a_tiny_target_it_reaches_gets_looser_reruns_too(tmp_path):
    """The turbine (genus 11) at 180 triangles, a target it reaches: under the usual checks the
    collapses left a max of 11.5 % of the diagonal (bench_quality.py's sampling), where at its
    floor of 138 triangles, under the floor's looser reruns, it had 5.7 %. A tiny result now gets
    three more reruns under the floor's checks, kept where they lower the max more than they
    raise the mean (refine.cpp, loose_rerun). By MeshLab's own Hausdorff, against its quadric
    collapse at the same count (which keeps the topology here): max 2.05 and mean 1.33 times
    MeshLab's before, 0.52 and 0.69 now."""
    pytest.importorskip("pymeshlab")
    from test_large_first_pass import ours_and_meshlabs

    v, t = reference.read_off(DATA / "genus_positive/cgal_turbine.off")
    mesh = Mesh(v, t)
    r = mesh.decimate(target_triangles=180, seed=0)
    assert r.num_triangles == 180
    check_output(mesh, r, reference.invariants(len(v), t))
    (our_max, our_mean), (their_max, their_mean) = ours_and_meshlabs(tmp_path, np.asarray(v), np.asarray(t), r)
    assert our_max <= 0.75 * their_max, (our_max, their_max)
    assert our_mean <= 0.85 * their_mean, (our_mean, their_mean)
