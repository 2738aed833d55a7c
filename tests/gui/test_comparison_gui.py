"""TopStoc next to Blender's own Decimate modifier (Collapse) in a real Blender window: the
original, Collapse and TopStoc's default Guided Decimate at the same triangle count, wireframe on
(docs/benchmarks.md's comparison picture: TOPSTOC_DOC_SHOTS=docs/images). The figures in the captions are
measured here with the project's Hausdorff distance; the benchmark over many meshes and peers is
tests/bench/bench_quality.py."""

import pytest

from conftest import DATA


@pytest.fixture(scope="module")
def report(gui, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("comparison_gui")
    scene = gui.scene(tmp / "dragon.blend", "--mesh", DATA / "genus0" / "cgal_ChineseDragon-10kv.off",
                      "--name", "Dragon")
    return gui.run("comparison_script.py", scene, tmp / "out", 0.05)


def test_gui_checks_pass(report):
    assert report["checks"] and all(report["checks"].values()), report["checks"]


def test_counts_match(report):
    counts = report["values"]["triangles"]
    assert abs(counts["topstoc"] - 0.05 * counts["original"]) <= 0.02 * counts["original"], counts
    assert abs(counts["collapse"] - counts["topstoc"]) <= 0.01 * counts["topstoc"], counts


def test_default_result_not_worse_than_collapse(report):
    """The default result's mean error stays near Blender's Collapse on this mesh (the issue that
    made quality the default measured 2.8x worse here); 1.25x leaves room for sampling noise."""
    errors = report["values"]["errors_percent_of_diagonal"]
    assert errors["topstoc"]["mean"] <= 1.25 * errors["collapse"]["mean"], errors
