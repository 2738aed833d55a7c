"""Issue 40's figures in bench_quality.py: a peer enters them only where it reached our count."""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "bench"))

from quality_goals import goal_ratios, left_out  # noqa: E402


def tool(triangles, mean, worst):
    return {"triangles": triangles, "mean": mean, "max": worst}


def case(**peers):
    return {"tools": {"topstoc quality": tool(100, 0.2, 2.0), **peers}}


def test_a_peer_stopped_far_above_our_count_is_left_out():
    c = case(**{"Blender Collapse": tool(101, 0.4, 3.0), "MeshLab": tool(500, 0.01, 0.1),
                "meshopt_simplify": tool(96, 0.3, 1.0)})
    assert left_out(c) == ["MeshLab"]
    assert goal_ratios(c) == (0.2 / 0.4, 2.0 / 1.0)


def test_the_count_slack_is_five_percent_and_two_triangles():
    assert left_out(case(MeshLab=tool(107, 0.1, 1.0))) == []
    assert left_out(case(MeshLab=tool(108, 0.1, 1.0))) == ["MeshLab"]


def test_no_peer_at_our_count_gives_no_figure():
    c = case(**{"Blender Collapse": tool(300, 0.1, 1.0), "fast-simplification": tool(99, 0.5, 4.0)})
    mean, worst = goal_ratios(c)
    assert mean is None and worst == 0.5


def test_exact_results_compare_as_ties():
    c = {"tools": {"topstoc quality": tool(100, 1e-9, 1e-9), "MeshLab": tool(100, 1e-12, 0.0)}}
    assert goal_ratios(c) == (1.0, 1.0)


def test_peers_that_changed_the_topology_leave_the_kept_topology_figures():
    changed = {**tool(100, 0.1, 1.0), "topology": False}
    kept = {**tool(100, 0.4, 4.0), "topology": True}
    c = case(**{"Blender Collapse": changed, "MeshLab": kept, "meshopt_simplify": {**tool(100, 0.1, 0.5), "topology": False}})
    assert goal_ratios(c) == (0.2 / 0.1, 2.0 / 0.5)
    assert goal_ratios(c, kept_topology=True) == (0.2 / 0.4, 2.0 / 4.0)
    assert goal_ratios(case(**{"Blender Collapse": changed}), kept_topology=True) == (None, None)
