"""The bounded Hausdorff estimate (topstoc.core.api.error_estimate): estimate <= exact max <= upper.

The exact max comes from an independent measure: CGAL's bounded_error_Hausdorff_distance (a
peer program, skipped when not built) on real meshes, and closed forms on meshes whose
Hausdorff distance is known exactly.
"""

import importlib

import numpy as np
import pytest

import topstoc
from peer_runs import cgal_hausdorff, peer, read_off, write_off

estimates = importlib.import_module(topstoc.__name__ + ".core.api.error_estimate")
engine = importlib.import_module(topstoc.__name__ + ".core.support.native").engine


def grid(n: int, z=None):
    """(n+1)^2 vertices on the unit square at height z (one per vertex, or 0), 2 n^2 triangles."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), np.zeros(x.size) if z is None else z], axis=1)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    v = (i * (n + 1) + j).ravel()
    triangles = np.concatenate([np.stack([v, v + n + 1, v + 1], 1), np.stack([v + 1, v + n + 1, v + n + 2], 1)])
    return vertices, triangles.astype(np.int32)


@pytest.mark.parametrize("gap, queries", [(estimates.DEFAULT_GAP, None), (0.25, 100_000), (0.25, 40)])
def test_a_raised_vertex_is_bracketed(gap, queries):
    # One interior vertex of a flat grid raised by h: the symmetric max is exactly h (the raised
    # vertex's distance to the plane; every point of the plane is nearer the pyramid than that).
    flat = grid(20)
    z = np.zeros(len(flat[0]))
    z[10 * 21 + 10] = 0.07
    raised = grid(20, z)
    bound = estimates.estimate_error(flat, raised, gap, queries)
    assert bound.estimate <= 0.07 + 1e-12
    assert bound.upper >= 0.07 - 1e-12
    # converged with a generous budget; otherwise the bracket still holds, only wider
    assert bound.converged or queries != 100_000
    if bound.converged:
        assert bound.upper <= bound.estimate * (1 + gap) + 1e-12


def test_a_shifted_copy_is_bracketed_and_the_exact_bracket_is_tight():
    # A fine grid and a coarse one lifted by 0.03: every point of either is 0.03 from the other.
    fine, coarse = grid(32), grid(4)
    coarse = (coarse[0] + [0.0, 0.0, 0.03], coarse[1])
    for bound in (estimates.estimate_error(fine, coarse), estimates.exact_error(fine, coarse)):
        assert bound.estimate <= 0.03 + 1e-12 <= bound.upper + 2e-12
    exact = estimates.exact_error(fine, coarse)
    assert exact.exact and exact.as_dict()["kind"] == "exact"
    assert exact.upper <= exact.estimate * (1 + estimates.EXACT_GAP) + 1e-12


PAIRS = [("genus0/cgal_fandisk.off", "fast", 0.1), ("genus0/cgal_fandisk.off", "quality", 0.02),
         ("genus_positive/cgal_elephant.off", "quality", 0.1), ("genus_positive/cgal_knot1.off", "fast", 0.05)]


@pytest.mark.parametrize("name, mode, ratio", PAIRS)
@pytest.mark.parametrize("queries", [None, 100_000, 300])
@pytest.mark.heavy
def test_agrees_with_cgal(data_dir, tmp_path, name, mode, ratio, queries):
    if peer("cgal_hausdorff") is None:
        pytest.skip("the peer program cgal_hausdorff was not built (libcgal-dev)")
    source = data_dir / name
    a = read_off(source)
    b = topstoc.Mesh(*a).decimate(ratio=ratio, seed=1, mode=mode)
    decimated = tmp_path / "decimated.off"
    write_off(decimated, b.vertices, b.triangles)
    cgal = cgal_hausdorff(source, decimated, error_bound_fraction=2e-5, mean_samples=1000)
    truth = max(cgal["forward"]["max_bounded"], cgal["backward"]["max_bounded"])
    bound = estimates.estimate_error(a, (b.vertices, b.triangles), queries=queries)
    print(f"{name} {mode} {ratio} queries {queries}: estimate {bound.estimate:.6g} <= CGAL {truth:.6g} "
          f"<= upper {bound.upper:.6g} (converged {bound.converged})")
    assert bound.estimate <= truth + cgal["error_bound"]
    assert bound.upper >= truth - cgal["error_bound"]
    for side, ours in (("forward", bound.forward), ("backward", bound.backward)):
        assert ours[0] <= cgal[side]["max_bounded"] + cgal["error_bound"] <= ours[1] + 2 * cgal["error_bound"]


#: (mesh, mode, ratio): on CAD (fandisk) the quick bound alone does not settle a result nearly on
#: the original over long sides; the walk it falls back on then does.
QUICK_CASES = [("genus0/cgal_fandisk.off", "quality", 0.1), ("genus0/cgal_armadillo.off.gz", "fast", 0.02),
               ("genus_positive/cgal_elephant.off", "quality", 0.01),
               ("open_boundary/cgal_mushroom.off", "quality", 0.01),
               ("nonmanifold_degenerate/dragon_vrip_res4.ply.gz", "fast", 0.02),
               ("open_boundary/kivy_suzanne_monkey.obj", "quality", 0.1)]


@pytest.mark.parametrize("name, mode, ratio", QUICK_CASES)
@pytest.mark.heavy
def test_the_quick_bound_holds_against_the_exact_max_and_is_near_it(data_dir, name, mode, ratio):
    # The quick bound (the default for big originals: no search structure over the original's
    # triangles) against the exact bracketed max, side by side: its upper bound is never below the
    # exact max (each side too), its estimate never above. It settles: the upper bound is within
    # 25 % of its estimate, within 1.5x of the exact max, the estimate within 10 %, and its mean
    # estimates the mean distance from the original (one vertex per grid cell, unweighted), within 40 %.
    from topstoc.core.api.hausdorff import hausdorff
    from topstoc.core.api.io import read_mesh
    data = read_mesh(data_dir / name)
    original = (data.vertices, data.triangles)
    b = topstoc.Mesh(*original).decimate(ratio=ratio, seed=1, mode=mode)
    result = (b.vertices, b.triangles)
    quick, exact = estimates.estimate_error(original, result, quick=True), estimates.exact_error(original, result)
    assert quick.upper >= exact.estimate and quick.estimate <= exact.upper
    assert quick.forward[1] >= exact.forward[0] and quick.backward[1] >= exact.backward[0]
    assert quick.forward[0] <= exact.forward[1] and quick.backward[0] <= exact.backward[1]
    assert quick.converged and quick.upper <= (1 + estimates.DEFAULT_GAP) * quick.estimate
    assert quick.upper <= 1.5 * exact.upper
    assert quick.estimate >= 0.9 * exact.estimate
    measured = hausdorff(original, result, samples=200_000, percentile=0).forward.mean
    assert 0.6 * measured <= quick.mean <= 1.4 * measured


def test_a_result_point_found_too_far_is_measured_on_later_results():
    # The original: a 10 x 10 grid with a 2 x 2 cell hole centred at (0.5, 0.2); a result of two
    # triangles spans the hole, so its farthest point from the original is the hole's centre, 0.1
    # away (closed form), and no vertex, centroid or edge midpoint of it lies in the hole.
    vertices, triangles = grid(10)
    centre = vertices[triangles].mean(axis=1)
    keep = ~((np.abs(centre[:, 0] - 0.5) < 0.1) & (np.abs(centre[:, 1] - 0.2) < 0.1))
    original = (vertices, triangles[keep])
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    results = [(square, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)),
               (square, np.array([[0, 1, 3], [1, 2, 3]], dtype=np.int32))]
    surface = importlib.import_module(topstoc.__name__ + ".core.api.hausdorff").as_surface(original)
    sampled = estimates.SampledError(original, surface)
    assert max(sampled(result) for result in results) < 1e-12  # the spread points miss the hole
    decided = estimates.decide_error(original, results[0], 0.05, original_surface=surface)
    assert decided.estimate > 0.05 and decided.witness is None  # the original lies on the result
    # the witness: a point of the result (in the hole's plane) farther than the bound
    assert abs(decided.result_witness[2]) < 1e-12
    assert engine.closest_points(surface, decided.result_witness.reshape(1, 3))["distance"][0] > 0.05
    sampled.add_result_witness(decided.result_witness)
    # each result's closest point to it is measured: attained, above the bound, at most the exact 0.1
    for result in results:
        assert 0.05 < sampled(result) <= 0.1 + 1e-12


def test_the_quick_bound_measures_the_open_corners_rather_than_bracketing_their_triangles(data_dir):
    # Armadillo at 10 % (quality): the triangles of the original that their corners' bounds through
    # one triangle of the result per grid cell leave open get those corners measured exactly, which
    # settles nearly all of them; only the rest is handed to the exact bracket (71 % of the
    # triangles before, three queries each and more). The forward bracket still holds the exact
    # max and stays within the gap.
    from topstoc.core.api.hausdorff import as_surface
    from topstoc.core.api.io import read_mesh
    data = read_mesh(data_dir / "genus0/cgal_armadillo.off.gz")
    original = (data.vertices, data.triangles)
    b = topstoc.Mesh(*original).decimate(ratio=0.1, seed=1)
    result = (b.vertices, b.triangles)
    found = engine.quick_hausdorff_bound(as_surface(original), as_surface(result), tolerance=0.25)
    assert found["refined"] < 0.1 * len(data.triangles)
    assert found["queries"] < 2 * len(data.vertices)
    exact = estimates.exact_error(original, result)
    assert found["forward_lower"] <= exact.forward[1] and found["forward_upper"] >= exact.forward[0]
    assert found["forward_upper"] <= 1.25 * found["forward_lower"] * (1 + 1e-12)


@pytest.mark.parametrize("height", [0.03, 0.01, 0.003])
def test_the_quick_bound_settles_a_flat_result_over_a_dome_by_more_splits_where_few_triangles_need_them(height):
    # The original: a smooth dome of the given height over the unit square (a 200 x 200 grid); the
    # result: the square's two flat triangles. The backward max lies at the dome's top, where the
    # square's shared edge passes: both triangles need pieces a few times smaller than the height
    # there. At 0.03 that takes more than the 256 splits a triangle first gets and fewer than the
    # retry's 4096, so the backward side settles within the gap on its own (it was 1.78 times its
    # estimate, leaving the whole side to the exact walk); at 0.01 the dome's planes beneath the
    # pieces settle them (the splits alone left 4.7 times the estimate); at 0.003 too, since pieces
    # over fewer than two of the dome's triangles are tried as well (it had stayed at its first
    # bound). Both sides hold the exact bracket's max.
    from topstoc.core.api.hausdorff import as_surface
    n = 200
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    original = as_surface(grid(n, (height * np.sin(np.pi * x) * np.sin(np.pi * y)).ravel()))
    square = as_surface((np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float),
                         np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)))
    found = engine.quick_hausdorff_bound(original, square, tolerance=0.25)
    estimate = max(found["forward_lower"], found["backward_lower"])
    assert found["backward_upper"] <= 1.25 * estimate * (1 + 1e-12)
    for side, (a, b) in (("forward", (original, square)), ("backward", (square, original))):
        exact = engine.bracket_one_sided_max(a, b, tolerance=1e-3, max_queries=estimates.EXACT_QUERIES)
        assert exact["converged"]
        assert found[side + "_lower"] <= exact["upper"] and found[side + "_upper"] >= exact["lower"]
    assert abs(estimate - height) <= 1e-3 * height  # attained at the top, where the max is


@pytest.mark.parametrize("ratio", [0.01, 0.1])
def test_the_quick_bound_settles_a_result_over_many_small_triangles_by_their_planes_beneath(ratio):
    # A smooth torus of 160,000 triangles at 1 % and 10 %: each result triangle lies over 10-100 of
    # the original's, far closer to them than its own size. Their planes' heights beneath a piece of
    # it bound it at once (projected_bound_over), where the distance's Lipschitz bound split it down
    # to about the deviation (710,000 walks at 1 %; at 10 % the splits ran out and the bracket was
    # 8.8 times its estimate). The bracket holds the exact max on both sides and settles.
    from meshgen import torus
    from topstoc.core.api.hausdorff import as_surface
    original = torus(400, 200)
    b = topstoc.Mesh(*original).decimate(ratio=ratio, seed=1)
    result = (b.vertices, b.triangles)
    found = engine.quick_hausdorff_bound(as_surface(original), as_surface(result), tolerance=0.25)
    assert found["grid_queries"] < 4 * len(b.triangles)  # the walks of the result's vertices and a few pieces
    exact = assert_holds_the_exact_bracket(found, original, result)
    estimate = max(found["forward_lower"], found["backward_lower"])
    assert max(found["forward_upper"], found["backward_upper"]) <= 1.25 * estimate * (1 + 1e-12)
    assert estimate >= 0.9 * exact.estimate


def test_the_quick_bound_settles_a_result_lying_on_its_original_by_the_triangles_beneath(data_dir):
    # The knot subdivided twice (each triangle into 16 coplanar ones) and decimated to a tenth: the
    # result lies on its original up to rounding. Each of its triangles spans about ten of the
    # original's, and the boundary of those beneath it runs through its corners, where the
    # original's surface turns away: the bound beneath allows that within the coordinates'
    # rounding (its margin had been a billionth of the piece's size, and pieces over fewer than two
    # triangles were not tried), so the backward side settles instead of stopping at 1.6e-4 of the
    # diagonal. Both sides hold the exact bracket.
    from topstoc.core.api.hausdorff import as_surface
    original, result = subdivided_and_decimated(data_dir / "genus_positive" / "cgal_knot1.off", 2, 0.1)
    a = as_surface(original)
    found = engine.quick_hausdorff_bound(a, as_surface(result), tolerance=0.25)
    assert found["backward_upper"] < 1e-9 * a.diagonal
    assert_holds_the_exact_bracket(found, original, result)


@pytest.mark.parametrize("name", ["genus0/cgal_fandisk.off", "genus_positive/cgal_anchor_dense.off"])
def test_the_quick_bound_settles_a_cad_result_lying_on_its_subdivided_original(data_dir, name):
    # A CAD mesh subdivided once (each triangle into four coplanar ones) and decimated to a tenth.
    # Fandisk: pieces of the result near the original's creases have corners whose nearest triangles
    # lie on the crease's two faces; bounded on the crease's two sides (the edge cut), and beneath
    # again once a piece is 16 times smaller than where that failed, the backward side settles (it
    # had stayed 93 times the estimate, left to the exact walk). The anchor: the result lies within
    # 5.6e-7 of the diagonal of its original, and where a triangle of either lies across a vertex of
    # the other its corners' nearest triangles share no edge; bounded sector by sector around that
    # vertex (the fan cut), both sides settle (they had stayed 189 and 3,224 times the estimate).
    # Both sides hold the exact bracket.
    from topstoc.core.api.hausdorff import as_surface
    original, result = subdivided_and_decimated(data_dir / name, 1, 0.1)
    found = engine.quick_hausdorff_bound(as_surface(original), as_surface(result), tolerance=0.25)
    estimate = max(found["forward_lower"], found["backward_lower"])
    assert max(found["forward_upper"], found["backward_upper"]) <= 1.25 * estimate * (1 + 1e-12)
    assert_holds_the_exact_bracket(found, original, result)


def test_the_report_settles_at_its_resolution_where_a_result_lies_on_its_original(data_dir):
    # The elephant subdivided twice and decimated to 8 %: the result lies on its original up to
    # rounding (the max is 2.4e-11 of the diagonal). The quick bound takes the report's resolution:
    # pieces under it count as settled instead of being split toward the rounding (the backward side
    # had stopped at 1e-5 of the diagonal, 430,000 times its estimate, and was left to the exact
    # walk). The report converges without the walk, and its bracket holds the exact one's.
    from topstoc.core.api.hausdorff import as_surface
    original, result = subdivided_and_decimated(data_dir / "genus_positive" / "cgal_elephant.off", 2, 0.08)
    a = as_surface(original)
    found = engine.quick_hausdorff_bound(a, as_surface(result), tolerance=0.25, resolution=estimates.RESOLUTION)
    assert max(found["forward_upper"], found["backward_upper"]) <= 1.25 * estimates.RESOLUTION * a.diagonal
    report = estimates.estimate_error(original, result, quick=True)
    assert report.converged
    assert report.queries == found["queries"] + found["grid_queries"]  # no exact walk after the bound
    exact = estimates.exact_error(original, result)
    assert report.estimate <= exact.upper and report.upper >= exact.estimate
    with pytest.raises(ValueError, match="resolution"):
        engine.quick_hausdorff_bound(a, as_surface(result), tolerance=0.25, resolution=-1.0)


def test_the_quick_bound_holds_around_a_fan_centre_through_its_search_tree():
    # A cylinder whose caps are fans of 5,000 slivers each: the centres' stars are searched through a
    # tree of their own (a pass over all of a centre's triangles for every point near it made a
    # fanned cap's bound take minutes). Both sides still hold the exact bracket's max.
    from fan_meshes import cylinder_caps
    from topstoc.core.api.hausdorff import as_surface
    original = cylinder_caps(5000, 4)
    for ratio in (0.002, 0.05):
        b = topstoc.Mesh(*original).decimate(ratio=ratio, seed=1)
        found = engine.quick_hausdorff_bound(as_surface(original), as_surface((b.vertices, b.triangles)), tolerance=0.25)
        exact = estimates.exact_error(original, (b.vertices, b.triangles))
        for side in ("forward", "backward"):
            ours, theirs = (found[side + "_lower"], found[side + "_upper"]), getattr(exact, side)
            assert ours[0] <= theirs[1] and ours[1] >= theirs[0]


def bumpy(n: int = 30):
    """A grid with a smooth bump field (heights up to 0.05): closest points vary across it."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    return grid(n, (0.05 * np.sin(7 * x) * np.cos(5 * y)).ravel())


def test_closest_points_within_stops_only_for_points_that_close():
    # Each point's exact nearest distance d (no ``within``) against the answer with ``within`` w,
    # points in random order (the hint chained from the previous point is far): a point farther
    # than w gets the same exact answer; a nearer one a point of the surface at distance d' with
    # d <= d' <= w (attained, not necessarily the nearest), and for many d' > d (it stopped early).
    vertices, triangles = bumpy()
    surface = importlib.import_module(topstoc.__name__ + ".core.api.hausdorff").as_surface((vertices, triangles))
    rng = np.random.default_rng(3)
    points = rng.uniform([-0.2, -0.2, -0.3], [1.2, 1.2, 0.3], size=(4000, 3))
    exact = engine.closest_points(surface, points)
    for within in (0.05, 0.2):
        found = engine.closest_points(surface, points, within)
        far = exact["distance"] > within
        assert far.any() and (~far).any()
        assert np.array_equal(found["distance"][far], exact["distance"][far])
        assert np.array_equal(found["triangle"][far], exact["triangle"][far])
        near = ~far
        assert np.all(found["distance"][near] >= exact["distance"][near] - 1e-12)
        assert np.all(found["distance"][near] <= within + 1e-12)
        # the point returned is at the distance returned
        assert np.allclose(np.linalg.norm(found["point"] - points, axis=1), found["distance"], atol=1e-12)
        assert np.mean(found["distance"][near] > exact["distance"][near] + 1e-9) > 0.2
    with pytest.raises(ValueError, match="within"):
        engine.closest_points(surface, points, -1.0)


def test_the_sampled_estimate_with_within_gives_the_same_verdict(data_dir):
    # Decimations of fandisk at several counts, each estimated in full and deciding a bound w
    # (0.5x, 1x, 2x its full value): the same verdict; above w a distance attained above w (the
    # first chunk's), within it a value between the full estimate and w.
    from topstoc.core.api.hausdorff import as_surface
    vertices, triangles = read_off(data_dir / "genus0" / "cgal_fandisk.off")
    sampled = estimates.SampledError((vertices, triangles), as_surface((vertices, triangles)))
    for count in (200, 1000, 3000):
        result = topstoc.Mesh(vertices, triangles).decimate(target_vertices=count, seed=1, mode="fast")
        full = sampled(result)
        assert full > 0
        for within in (0.5 * full, full, 2 * full):
            decided = sampled(result, within)
            assert (decided <= within) == (full <= within)
            if full > within:
                assert within < decided <= full
            else:
                assert full - 1e-15 <= decided <= within
            # exact above a share of it: the same value, measured again in full where below
            assert sampled(result, exact_above=within) == full


def test_a_failing_verdict_stops_at_the_first_chunk_beyond_the_bound(data_dir, monkeypatch):
    # The points each estimate sends to the engine, counted: deciding a bound half the full
    # estimate (the result fails) measures fewer than the full estimate, deciding twice it (passes)
    # measures them all; a place found too far before is measured first, so a result that keeps
    # it fails on its first chunk.
    from topstoc.core.api.hausdorff import as_surface
    vertices, triangles = read_off(data_dir / "genus0" / "cgal_fandisk.off")
    original = as_surface((vertices, triangles))
    sampled = estimates.SampledError((vertices, triangles), original)
    measured = []
    closest = engine.closest_points

    class Counting:
        def __getattr__(self, name):
            return getattr(engine, name)

        def closest_points(self, surface, points, *args):
            measured.append(len(points))
            return closest(surface, points, *args)

    monkeypatch.setattr(estimates, "engine", Counting())
    for count in (300, 3000):
        result = topstoc.Mesh(vertices, triangles).decimate(target_vertices=count, seed=1, mode="fast")
        measured.clear()
        full = sampled(result)
        every = sum(measured)
        measured.clear()
        assert sampled(result, 2 * full) <= 2 * full and sum(measured) == every
        measured.clear()
        assert sampled(result, 0.5 * full) > 0.5 * full and sum(measured) < every
    # the far point of the last result, found by the exact check, joins the points: measured first
    decided = estimates.decide_error((vertices, triangles), result, 0.5 * full, original_surface=original)
    assert decided.estimate > 0.5 * full
    if decided.witness is not None:
        sampled.add_witness(decided.witness)
    if decided.result_witness is not None:
        sampled.add_result_witness(decided.result_witness)
    measured.clear()
    assert sampled(result, 0.5 * full) > 0.5 * full
    assert sum(measured) <= len(sampled.points) - sampled.spread + 2 + len(sampled.result_witnesses)


def test_the_threshold_walk_decides_as_the_exact_bracket(data_dir):
    # Fandisk and the elephant decimated in both modes: the threshold walk (decide_error) against
    # the exact bracket (exact_error, every side converged to 1e-3): below its estimate it fails
    # with a distance attained above the threshold, above its upper bound (outside the exact gap)
    # it passes with an upper bound within the threshold.
    for name, count, mode in [("genus0/cgal_fandisk.off", 400, "quality"), ("genus0/cgal_fandisk.off", 3000, "fast"),
                              ("genus_positive/cgal_elephant.off", 250, "quality"),
                              ("genus_positive/cgal_elephant.off", 2000, "fast")]:
        vertices, triangles = read_off(data_dir / name)
        result = topstoc.Mesh(vertices, triangles).decimate(target_vertices=count, seed=1, mode=mode)
        exact = estimates.exact_error((vertices, triangles), result)
        assert exact.converged
        for threshold in (0.5 * exact.estimate, 0.99 * exact.estimate):
            decided = estimates.decide_error((vertices, triangles), result, threshold)
            assert threshold < decided.estimate <= exact.upper and decided.upper > threshold
        for threshold in (1.01 * exact.upper, 1.5 * exact.upper, 3 * exact.upper):
            decided = estimates.decide_error((vertices, triangles), result, threshold)
            assert exact.estimate <= decided.upper <= threshold and decided.estimate <= exact.upper


def test_the_threshold_walk_measures_each_shared_vertex_once(data_dir):
    # A decimated fandisk as an indexed mesh and as a soup (three vertices of its own per
    # triangle: the same triangles, so the same tree and the same distances): the walk brackets
    # both alike, and the indexed one, whose corners are shared, makes fewer queries.
    vertices, triangles = read_off(data_dir / "genus0" / "cgal_fandisk.off")
    hausdorff = importlib.import_module(topstoc.__name__ + ".core.api.hausdorff")
    original = hausdorff.as_surface((vertices, triangles))
    result = topstoc.Mesh(vertices, triangles).decimate(target_vertices=3000, seed=1, mode="fast")
    soup_vertices = np.asarray(result.vertices)[np.asarray(result.triangles)].reshape(-1, 3)
    soup = hausdorff.as_surface((soup_vertices, np.arange(len(soup_vertices), dtype=np.int32).reshape(-1, 3)))
    indexed = hausdorff.as_surface(result)
    exact = estimates.exact_error((vertices, triangles), result)
    for threshold in (0.5 * exact.estimate, 1.5 * exact.upper):
        found = [engine.bracket_one_sided_max(surface, original, tolerance=estimates.EXACT_GAP,
                                              max_queries=estimates.EXACT_QUERIES, threshold=threshold)
                 for surface in (indexed, soup)]
        assert (found[0]["upper"] <= threshold) == (found[1]["upper"] <= threshold)
        assert (found[0]["lower"] > threshold) == (found[1]["lower"] > threshold)
    assert found[0]["queries"] < 0.8 * found[1]["queries"]


def test_z_order_keeps_every_point_and_orders_them_by_place():
    # A permutation of the points; consecutive points along it are far nearer one another than in
    # the input's shuffled order (the closest-point queries' hints then land near their answers).
    rng = np.random.default_rng(5)
    points = rng.uniform(-1, 3, size=(20_000, 3))
    order = estimates._z_order(points)
    assert np.array_equal(np.sort(order), np.arange(len(points)))
    step = lambda p: np.linalg.norm(np.diff(p, axis=0), axis=1).mean()  # noqa: E731
    assert step(points[order]) < 0.1 * step(points)
    assert len(estimates._z_order(np.empty((0, 3)))) == 0
    assert np.array_equal(estimates._z_order(np.ones((4, 3))), np.arange(4))  # all in one place: as given


def subdivided_and_decimated(path, levels: int, ratio: float):
    """A test mesh subdivided into coplanar triangles (meshgen.subdivide) and its decimation: a
    result that can lie on its original, the hardest case for a bound."""
    from meshgen import subdivide
    from topstoc.core.api.io import read_mesh
    mesh = read_mesh(path)
    original = subdivide(mesh.vertices, mesh.triangles, levels)
    b = topstoc.Mesh(*original).decimate(ratio=ratio, seed=1)
    return original, (b.vertices, b.triangles)


def assert_holds_the_exact_bracket(found: dict, original, result):
    """Each side of the quick bound's bracket meets the exact bracket's (both hold the true max);
    returns the exact one."""
    exact = estimates.exact_error(original, result)
    for side in ("forward", "backward"):
        ours, theirs = (found[side + "_lower"], found[side + "_upper"]), getattr(exact, side)
        assert ours[0] <= theirs[1] and ours[1] >= theirs[0]
    return exact
