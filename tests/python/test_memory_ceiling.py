"""Peak memory of prepare + decimate per input triangle on a 2M-triangle mesh, measured in a
fresh process (tests/memory_peak.py): a ceiling that catches a change adding a per-triangle
array, and issue 39's goals (100 bytes a triangle in quality mode, reached; 70 in fast mode, not
yet: 80.3; input arrays included). A memory figure, not a time: the same on a busy machine. A mesh
this size keeps no floods by default (Mesh.KEEP_FLOODS_BELOW): this is a one-off decimation's
peak."""

import pytest

import memory_peak

pytestmark = pytest.mark.skipif(not memory_peak.available(), reason="needs /proc/self/clear_refs (Linux)")

TRIANGLES = 2_000_000
#: What the engine reaches now (fast 80.3, quality 93.1 alone, about 1.5 more inside the whole
#: test run; both the decimation's, the preparation's being the one-ring pass at 77.6), with a
#: margin below one per-vertex array of 8 bytes (4 bytes a triangle) over those figures. Quality
#: mode's first pass keeps 8 times the target (80,000 vertices here; it kept the target and
#: 10,000 more, at 80.7), whose collapser's state is the difference. Before: 84.5-84.6 (the
#: one-ring pass's faces above each vertex held whole to its end, the components as 4 bytes a
#: vertex, the manifold flags kept when all set); main before that: 95.5, 94.8.
CEILING = {"quality": 97.0, "fast": 83.5}
#: The preparation's own peak (77.5-77.6 alone; before 84.5) and what the prepared mesh holds
#: (73.2-73.7: its arrays and the input's 24; before 76.0-76.2), the latter with a margin below a
#: 4-byte per-vertex array.
PREPARE_CEILING, PREPARED_CEILING = 81.0, 75.5
#: Issue 39's goals.
GOAL = {"quality": 100, "fast": 70}


@pytest.fixture(scope="module")
def peaks():
    return {mode: memory_peak.measure(TRIANGLES, mode) for mode in ("quality", "fast")}


@pytest.mark.parametrize("mode", ["quality", "fast"])
@pytest.mark.heavy
def test_peak_per_triangle_stays_under_the_ceiling(peaks, mode):
    figures = peaks[mode]
    assert figures["triangles"] > 0.99 * TRIANGLES and figures["topology_kept"]
    assert 0.009 * figures["vertices"] < figures["output_vertices"] < 0.011 * figures["vertices"]
    # the input arrays alone are 24 bytes a triangle: a figure below that measured nothing
    assert 24 < figures["bytes_per_triangle"] <= CEILING[mode], figures


def test_the_preparation_and_the_prepared_mesh_stay_under_their_ceilings(peaks):
    figures = peaks["quality"]
    assert 24 < figures["prepared_bytes_per_triangle"] <= PREPARED_CEILING, figures
    assert figures["prepared_bytes_per_triangle"] <= figures["prepare_bytes_per_triangle"] <= PREPARE_CEILING, figures


@pytest.mark.parametrize("mode", [
    "quality",
    pytest.param("fast", marks=pytest.mark.xfail(strict=True, reason="fast mode's goal is not reached yet "
                                                 "(see docs/benchmarks.md)"))])
def test_peak_per_triangle_meets_the_goal(peaks, mode):
    assert peaks[mode]["bytes_per_triangle"] <= GOAL[mode]


#: A closed scan with a few holes (shape_families.holed_scan), fast mode, above the size that
#: keeps floods: its borders need the edges and their face counts (30 bytes a triangle) and the
#: layout's border flags, not the faces of every edge, the vertex-face table or a sector per face
#: slot (before: 172.8 bytes a triangle; now 118.9, the closed torus 79.9), with a margin below
#: a 4-byte per-vertex array.
HOLED_CEILING = 121.0


@pytest.mark.heavy
def test_a_scan_with_a_few_holes_stays_under_its_ceiling():
    figures = memory_peak.measure(1_100_000, "fast", family="holed_scan")
    assert figures["topology_kept"] and 0.009 * figures["vertices"] < figures["output_vertices"] < 0.011 * figures["vertices"]
    assert 24 < figures["bytes_per_triangle"] <= HOLED_CEILING, figures
