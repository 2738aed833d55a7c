"""The batch's default error report (core/batch/mesh_asset.py's lod_error) is a converged bracket of
the symmetric Hausdorff max: ``hausdorff`` attained, ``hausdorff_upper`` guaranteed and within 25 %
of it, ``hausdorff_converged`` true, on meshes of several kinds (CAD, scans open and closed, a
modelled open mesh, a knot). The reference is the exact measurement of hausdorff.py, another code
path: 200,000 samples spread on each surface, then its own bracket of the max within 0.1 %."""

import numpy as np
import pytest

import topstoc
from topstoc.core.api.hausdorff import as_surface, hausdorff
from topstoc.core.api.io import read_mesh
from topstoc.core.batch.mesh_asset import lod_error

#: (mesh under tests/data, mode, ratio, kind)
CASES = [("genus0/cgal_fandisk.off", "quality", 0.1, "CAD"),
         ("genus_positive/cgal_anchor_dense.off", "quality", 0.05, "CAD"),
         ("nonmanifold_degenerate/dragon_vrip_res4.ply.gz", "fast", 0.1, "open scan, non-manifold"),
         ("open_boundary/cgal_elephant-with-holes.off", "quality", 0.1, "open, with holes"),
         ("genus0/cgal_armadillo.off.gz", "quality", 0.05, "closed scan"),
         ("open_boundary/kivy_suzanne_monkey.obj", "quality", 0.2, "modelled, open"),
         ("genus_positive/cgal_knot1.off", "fast", 0.02, "knot")]


@pytest.mark.parametrize("name, mode, ratio, kind", CASES)
def test_the_default_report_is_a_converged_bracket_of_the_exact_max(data_dir, name, mode, ratio, kind):
    data = read_mesh(data_dir / name)
    original = topstoc.Mesh(data.vertices, data.triangles)
    result = original.decimate(ratio=ratio, seed=1, mode=mode)
    entry = lod_error(original, result, None, original_surface=as_surface(original, "original"))
    truth = hausdorff((data.vertices, data.triangles), (result.vertices, result.triangles),
                      samples=200_000, percentile=0).symmetric
    print(f"{name} ({kind}) {mode} {ratio}: report [{entry['hausdorff']:.6g}, {entry['hausdorff_upper']:.6g}], "
          f"exact [{truth.max:.6g}, {truth.max_upper:.6g}]")
    assert truth.max_upper <= truth.max * 1.001 + 1e-12  # the reference itself is settled
    assert entry["hausdorff"] <= truth.max_upper * (1 + 1e-12)      # attained
    assert entry["hausdorff_upper"] >= truth.max * (1 - 1e-12)      # guaranteed
    assert entry["hausdorff_converged"] is True and entry["hausdorff_kind"] == "estimate"
    assert entry["hausdorff_upper"] <= 1.25 * entry["hausdorff"] * (1 + 1e-12)
    diagonal = np.linalg.norm(data.vertices.max(axis=0) - data.vertices.min(axis=0))
    assert entry["hausdorff_upper_relative"] == pytest.approx(entry["hausdorff_upper"] / diagonal)


def test_exact_on_request_is_within_the_default_bracket(data_dir):
    # --exact-error's bracket (0.1 %) lies inside the default one, on CAD.
    data = read_mesh(data_dir / "genus0/cgal_fandisk.off")
    original = topstoc.Mesh(data.vertices, data.triangles)
    result = original.decimate(ratio=0.05, seed=1)
    estimate, exact = lod_error(original, result, None), lod_error(original, result, None, exact=True)
    assert exact["hausdorff_kind"] == "exact" and exact["hausdorff_converged"]
    assert exact["hausdorff_upper"] <= exact["hausdorff"] * 1.001 + 1e-12
    assert estimate["hausdorff"] <= exact["hausdorff_upper"] and exact["hausdorff"] <= estimate["hausdorff_upper"]


def test_a_result_on_its_original_up_to_rounding_settles_at_the_resolution():
    # A subdivided icosphere decimated to 30 % gives back its flat faces: the max is rounding
    # (about 1e-13 of the diagonal), and no relative gap can settle it. The report settles it under
    # 1e-7 of the diagonal (error_estimate.RESOLUTION), still bracketing the exact max.
    import meshgen
    vertices, triangles = meshgen.subdivide(*meshgen.icosphere(2), 1)
    vertices = np.asarray(vertices) * 7.0 + [30.0, -12.0, 5.0]
    original = topstoc.Mesh(vertices, triangles)
    result = original.decimate(ratio=0.3, seed=1)
    entry = lod_error(original, result, None)
    truth = hausdorff((vertices, triangles), (result.vertices, result.triangles), samples=200_000,
                      percentile=0).symmetric
    diagonal = np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0))
    assert truth.max_upper < 1e-9 * diagonal  # the result lies on the original
    assert entry["hausdorff"] <= truth.max_upper * (1 + 1e-12) and entry["hausdorff_upper"] >= truth.max
    assert entry["hausdorff_converged"] is True
    assert entry["hausdorff_upper"] <= 1e-7 * diagonal * (1 + 1e-9)  # error_estimate.RESOLUTION


def _grid(n, half_width, height):
    """An n x n grid of cells over [-half_width, half_width] x [-1, 1], two triangles each, at
    z = height(x)."""
    x, y = np.meshgrid(np.linspace(-half_width, half_width, n + 1), np.linspace(-1.0, 1.0, n + 1))
    vertices = np.column_stack([x.ravel(), y.ravel(), height(x.ravel())])
    a = (np.arange(n)[None, :] + (n + 1) * np.arange(n)[:, None]).ravel()
    triangles = np.concatenate([np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])])
    return vertices, triangles


@pytest.mark.parametrize("slope", [1.0, 2.0])
def test_pieces_across_a_valley_settle_on_their_quarters_and_bracket_the_max(slope):
    # A flat sheet at height h = slope over a valley z = slope |x| (one triangle strip each side
    # of the crease x = 0), the sheet over |x| <= 1 where it stays above the valley: from the sheet
    # the distance is (h - slope |x|) / sqrt(1 + slope^2), largest over the crease, which no
    # vertex of the sheet's 7 x 7 cells lies on (the nearest are 1/7 away). The sheet's triangles
    # across the crease are left open by one triangle of the valley for the whole piece (their far
    # corner's distance to it exceeds 1.25 times the vertices' largest) and by the bound beneath
    # (heights are sqrt(1 + slope^2) times the distance): the old search needed a query between
    # the vertices (65). The bound over their quarters, each with its own side, settles them
    # without one. One that skipped the midpoints over the crease would come out under the exact max.
    from topstoc.core.support.native import engine
    h = slope
    sheet_mesh = _grid(7, 1.0, lambda x: np.full_like(x, h))
    sheet = as_surface(sheet_mesh, "sheet")
    valley = as_surface(_grid(2, 1.5, lambda x: slope * np.abs(x)), "valley")
    found = engine.bracket_symmetric_max(sheet, valley, tolerance=0.25, resolution=1e-7, max_queries=1_000_000)
    forward, exact = found["forward"], h / np.sqrt(1 + slope * slope)
    assert forward["lower"] <= exact * (1 + 1e-12) <= forward["upper"] * (1 + 2e-12)
    assert forward["upper"] <= 1.25 * forward["lower"] * (1 + 1e-12) and forward["converged"]
    # the sheet's vertices only (most walked to, a few looked up): no point between them was
    # measured, as one over the crease would have raised the lower bound above the vertices' max
    assert forward["queries"] <= 8 * 8
    vertex_max = float(engine.closest_points(valley, sheet_mesh[0])["distance"].max())
    assert forward["lower"] == pytest.approx(vertex_max, rel=1e-12)
    assert vertex_max < exact * (1 - 1e-3)


def test_pieces_straddling_an_edge_settle_on_their_two_halves(data_dir):
    # Fandisk at 10 %: many of the original's triangles lie across an edge (often a crease) of the
    # result, their corners nearest to the two triangles along it. Cut in two along that edge, each
    # half bounded by its own triangle (the distance to one triangle is convex, so it peaks at a
    # corner of the half), they settle without being split: beyond the two surfaces' vertices the
    # search made 42,304 queries before this bound, 30,300 with it. Each side's bracket still
    # holds that side's exact max (a side below the other's max would hide a wrong bound).
    from topstoc.core.api.error_estimate import estimate_error
    data = read_mesh(data_dir / "genus0/cgal_fandisk.off")
    original = topstoc.Mesh(data.vertices, data.triangles)
    result = original.decimate(ratio=0.1, seed=1)
    bound = estimate_error(original, result)
    truth = hausdorff((data.vertices, data.triangles), (result.vertices, result.triangles),
                      samples=200_000, percentile=0)
    for (lower, upper), exact in ((bound.forward, truth.forward), (bound.backward, truth.backward)):
        assert lower <= exact.max_upper * (1 + 1e-12) and upper >= exact.max * (1 - 1e-12)
    assert bound.converged and bound.upper <= 1.25 * bound.estimate * (1 + 1e-12)
    beyond_vertices = bound.queries - (data.num_vertices + result.num_vertices)
    assert beyond_vertices < 0.8 * 42_304


@pytest.mark.parametrize("name, ratio", [("genus_positive/cgal_anchor_dense.off", 0.05),
                                         ("genus0/cgal_armadillo.off.gz", 0.1),
                                         ("genus_positive/cgal_turbine.off", 0.1)])
def test_each_side_of_the_default_bracket_holds_its_exact_max(data_dir, name, ratio):
    # Both one-sided brackets against hausdorff.py's exact ones (another code path): the pieces
    # settled on their halves, quarters or the triangles beneath them on either side.
    from topstoc.core.api.error_estimate import estimate_error
    data = read_mesh(data_dir / name)
    original = topstoc.Mesh(data.vertices, data.triangles)
    result = original.decimate(ratio=ratio, seed=1)
    bound = estimate_error(original, result)
    truth = hausdorff((data.vertices, data.triangles), (result.vertices, result.triangles),
                      samples=200_000, percentile=0)
    for (lower, upper), exact in ((bound.forward, truth.forward), (bound.backward, truth.backward)):
        assert exact.max_upper <= exact.max * 1.001 + 1e-12
        assert lower <= exact.max_upper * (1 + 1e-12) and upper >= exact.max * (1 - 1e-12)
