"""docs/benchmarks.md is scripts/benchmarks_md.py's output from the saved results and notes, so a
figure changes only through a benchmark's JSON (or a note), and CI catches a hand edit."""

import importlib.util
import json

import pytest

from conftest import ROOT

spec = importlib.util.spec_from_file_location("benchmarks_md", ROOT / "scripts" / "benchmarks_md.py")
benchmarks_md = importlib.util.module_from_spec(spec)
spec.loader.exec_module(benchmarks_md)


def test_committed_benchmarks_md_is_the_scripts_output():
    assert (ROOT / "docs" / "benchmarks.md").read_text() == benchmarks_md.render(), \
        "docs/benchmarks.md is out of date: run python3 scripts/benchmarks_md.py"


def test_every_result_and_note_is_in_it():
    text = benchmarks_md.render()
    for path in sorted((ROOT / "docs" / "bench_results").glob("*.json")):
        assert f"(`{path.name}`)" in text
        figures = json.loads(path.read_text())
        assert f"- Machine: {figures['machine']}" in text and f"- Date: {figures['date']}" in text
    for path in sorted((ROOT / "docs" / "bench_notes").glob("*.md")):
        assert path.read_text().strip() in text


def _decimate_figures(simplify_ms):
    return {"benchmark": "tests/bench/bench_decimate.py", "machine": "test machine", "date": "2000-01-01",
            "repeats": 7, "mesh": {"name": "m.ply", "vertices": 1000, "triangles": 1996},
            "prepare_ms": 5.0, "first_ms": 80.0, "cold_quality_ms": 1500.0,
            "ratios": [{"ratio": 0.1, "vertices": 100, "triangles": 196, "fast_ms": 40.0,
                        "stages_ms": {"sampling": 4.0, "refine": 0.0}, "slider_step_ms": 8.0,
                        "slider_steps": 30, "slider_steps_updated": 29, "draft_ms": 30.0, "draft_step_ms": 4.0,
                        "quality_ms": 250.0, "quality_vertices": 100,
                        "meshopt_simplify_ms": simplify_ms, "meshopt_sloppy_ms": simplify_ms and 20.0}]}


def test_decimate_results_render_their_ratios():
    text = benchmarks_md.render_decimate("x.json", _decimate_figures(2000.0))
    row = [line for line in text.splitlines() if line.startswith("| 10 %") or line.startswith("| 10%")][0]
    cells = [cell.strip() for cell in row.strip("|").split("|")]
    # 2000 / 40 and 2000 / 250, computed here; the first decimation 2000 / 80
    assert cells == ["10% (100 vertices)", "40 ms", "8 ms (29 of 30 updated)", "30 ms / 4 ms", "250 ms",
                     "2.00 s", "20 ms", "50.0×", "8.0×"]
    assert "first decimation at 10% (prepare + fast decimate): 80 ms, 25.0× meshopt_simplify" in text
    assert "sampling 4 ms" in text and "refine" not in text


def test_missing_peer_is_a_dash_not_a_ratio():
    row = [line for line in benchmarks_md.render_decimate("x.json", _decimate_figures(None)).splitlines()
           if line.startswith("| 10%")][0]
    assert row.endswith("| — | — | — | — |")


def test_an_unknown_result_file_is_refused_by_name(tmp_path):
    path = tmp_path / "mystery.json"
    path.write_text(json.dumps({"benchmark": "tests/bench/bench_other.py"}))
    with pytest.raises(SystemExit, match="mystery.json"):
        benchmarks_md.render_result(path)


def _tool(mean, maximum, ar_mean, ar_max, topology=True, zero_area=0):
    return {"triangles": 100, "mean": mean, "max": maximum, "ar_mean": ar_mean, "ar_p99": ar_max,
            "ar_max": ar_max, "zero_area": zero_area, "topology": topology, "seconds": 0.1}


def test_quality_results_render_medians_of_our_figure_over_the_peers():
    ours = [_tool(1.0, 2.0, 1.2, 10.0), _tool(2.0, 2.0, 1.5, 40.0), _tool(3.0, 6.0, 1.3, 20.0, zero_area=1)]
    blender = [_tool(2.0, 1.0, 1.2, 20.0), _tool(1.0, 4.0, 3.0, 20.0, topology=False), _tool(4.0, 3.0, 2.6, 10.0)]
    cases = [{"mesh": f"m{i}.off", "ratio": 0.1, "input_triangles": 1000, "peer_triangles": 100,
              "tools": {"topstoc quality": a, "Blender Collapse": b, "MeshLab": None}}
             for i, (a, b) in enumerate(zip(ours, blender))]
    text = benchmarks_md.render_quality("q.json", {"benchmark": "tests/bench/bench_quality.py", "machine": "m",
                                                   "date": "2000-01-01", "samples": 1000, "cases": cases})
    row = [line for line in text.splitlines() if line.startswith("| Blender Collapse")][0]
    # mean: 0.5, 2, 0.75 -> 0.75 [2]; max: 2, 0.5, 2 -> 2 [2]; ar_mean: 1, 0.5, 0.5 -> 0.5 [1]; worst: 0.5, 2, 2
    assert row == "| Blender Collapse | 0.750× [2.00] | 2.000× [2.00] | 0.500× [1.00] | 2.000× [2.00] | 2/3 |"
    assert "| MeshLab | not available |" in text
    assert "3 cases (3 meshes × 10%)" in text
    assert "kept the topology in 3/3 cases, with 1 zero-area triangles and a worst aspect ratio of 40." in text


def test_quality_results_state_the_goals_per_case_and_name_the_worst():
    ours = [_tool(1.0, 2.0, 1.2, 10.0), dict(_tool(2.0, 2.0, 1.5, 40.0), over_budget=3, over_budget_reason="topology")]
    cases = [{"mesh": "a.off", "ratio": 0.005, "budget": None, "tools": {
                  "topstoc quality": ours[0], "Blender Collapse": _tool(2.0, 4.0, 1, 1),
                  "MeshLab": _tool(4.0, 1.0, 1, 1, topology=False),
                  "meshopt_simplify": None, "fast-simplification": _tool(0.5, 5.0, 1, 1)}},
             {"mesh": "b.off", "ratio": None, "budget": 50, "tools": {
                  "topstoc quality": ours[1], "Blender Collapse": None, "MeshLab": _tool(1.0, 1.0, 1, 1),
                  "meshopt_simplify": _tool(1.0, 4.0, 1, 1), "fast-simplification": None}}]
    text = benchmarks_md.render_quality("q.json", {"benchmark": "tests/bench/bench_quality.py", "machine": "m",
                                                   "date": "2000-01-01", "samples": 1000, "cases": cases})
    # mean over the better of Blender and MeshLab (fast-simplification is not in it): 1/2, 2/1
    assert "median 1.250 (goal ≤ 0.9), worst 2.00 (b.off at 50 triangles), above 1.0 in 1/2" in text
    # max over the best of all peers: 2/1, 2/1
    assert "max ÷ the best peer: median 2.000 (goal ≤ 1.0), worst 2.00 (a.off at 0.5%), above 1.15 in 2/2" in text
    # a's MeshLab changed the topology: without it the best max is Blender's 4, the better mean Blender's 2
    assert "| a.off | 0.5% | 100 | 0.50 | 2.00 | 0.50 | 0.50 | yes |" in text
    assert "| b.off | 50 triangles | 100 (topology) | 2.00 | 2.00 | 2.00 | 2.00 | yes |" in text
    assert ("max ÷ the best peer that kept the topology: median 1.250 (goal ≤ 1.0), worst 2.00 (b.off at 50 "
            "triangles), above 1.15 in 1/2") in text
    assert "2 cases (2 meshes × 0.5%, 50 triangles)" in text
    # a run with mode "best" too: the goal lines per mode, best's against the same peers
    cases[0]["tools"]["topstoc best"] = _tool(0.5, 1.0, 1.2, 10.0)
    text = benchmarks_md.render_quality("q.json", {"benchmark": "tests/bench/bench_quality.py", "machine": "m",
                                                   "date": "2000-01-01", "samples": 1000, "cases": cases})
    assert "max ÷ the best peer (quality mode): median 2.000 (goal ≤ 1.0)" in text
    assert "mean ÷ the better of Blender and MeshLab (best mode): median 0.250 (goal ≤ 0.9), worst 0.25" in text


def test_scale_results_render_ratios_and_growth():
    def mode(prepare, decimate, per_triangle):
        return {"prepare_s": prepare, "decimate_s": decimate, "bytes_per_triangle": per_triangle}
    figures = {"benchmark": "tests/bench/bench_scale.py", "machine": "test machine", "date": "2000-01-01",
               "ratio": 0.01, "sizes": [
                   {"triangles": 2000, "vertices": 1000, "quality": mode(1.0, 1.0, 99.6), "fast": mode(1.0, 0.5, 70.2),
                    "meshopt": {"simplify_s": 12.0, "sloppy_s": 1.0, "bytes_per_triangle": 120.0}},
                   {"triangles": 20000, "vertices": 10000, "quality": mode(9.0, 11.0, 90.0),
                    "fast": mode(10.0, 5.0, 60.0), "meshopt": None}]}
    text = benchmarks_md.render_scale("s.json", figures)
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines() if line.startswith("| 2")]
    # cold = prepare + decimate; 12 / 2 and 12 / 1.5; the second size has no peer
    assert rows[0] == ["2,000", "quality", "1.00 s", "1.00 s", "2.00 s", "100 B", "12.00 s", "6.0×", "120 B"]
    assert rows[1] == ["2,000", "fast", "1.00 s", "500 ms", "1.50 s", "70 B", "12.00 s", "8.0×", "120 B"]
    assert rows[2][4:] == ["20.00 s", "90 B", "—", "—", "—"]
    # 20 / 2 and 15 / 1.5
    assert "(10× the size) the cold time grew quality 10.0× and fast 10.0×" in text


def test_paired_results_render_the_median_of_the_pair_ratios():
    # new / old per pair: 0.9, 1.2, 1.0 -> median 1.0 (not 1.05 / 1.0, the ratio of the medians)
    pairs = [{"re-decimation": {"old": 100.0, "new": 90.0}}, {"re-decimation": {"old": 50.0, "new": 60.0}},
             {"re-decimation": {"old": 200.0, "new": 200.0}}]
    figures = {"benchmark": "tests/bench/bench_threads_paired.py", "machine": "m", "date": "2000-01-01",
               "load_average": 3.0, "mesh": "h.ply", "ratio": 0.1, "repeats": 3, "old": "A", "new": "B",
               "pairs": pairs, "median_ratio": {"re-decimation": 1.0}}
    text = benchmarks_md.render_paired("p.json", figures)
    row = [line for line in text.splitlines() if line.startswith("| re-decimation")][0]
    assert [cell.strip() for cell in row.strip("|").split("|")] == ["re-decimation", "100 ms", "90 ms", "1.000",
                                                                   "0.900–1.200"]
    assert "3 pairs of runs" in text and "## Paired runs: B against A" in text


def test_cleanup_results_render_the_anchors_and_their_ratio():
    voxel = {"genus": 6, "area_change": -0.16, "triangles": 900, "kept": 0.0, "seconds": 0.4}
    figures = {"benchmark": "tests/bench/bench_cleanup.py", "machine": "m", "date": "2000-01-01",
               "handles": [{"case": "10 arches", "triangles": 4392, "genus_before": 14, "genus_after": 4,
                            "area_change": 0.0008, "kept": 0.953, "patch_aspect": 1.28, "seconds": 0.6,
                            "loops_seconds": 0.5, "voxel": voxel, "pymeshfix_genus": 14},
                           {"case": "no peers", "triangles": 10, "genus_before": 1, "genus_after": 0,
                            "area_change": 0.001, "kept": 0.9, "patch_aspect": 1.1, "seconds": 0.1,
                            "loops_seconds": 0.1, "voxel": None, "pymeshfix_genus": None}],
               "holes": [{"k": 50, "triangles": 3000, "borders_before": 55,
                          "ours": {"borders_after": 5, "patch_aspect": 1.4, "rise": 0.0, "kept": 1.0, "seconds": 0.02},
                          "pymeshfix": None,
                          "meshlab": {"borders_after": 5, "patch_aspect": 4.19, "rise": 0.016, "kept": 1.0,
                                      "seconds": 0.39}}]}
    text = benchmarks_md.render_cleanup("c.json", figures)
    rows = {line.split("|")[1].strip(): [c.strip() for c in line.strip("|").split("|")]
            for line in text.splitlines() if line.startswith("| ")}
    # 0.16 / 0.0008, computed here
    assert rows["10 arches"][1:7] == ["4,392", "14 → 4", "6", "14", "+0.08 % / -16.00 %", "200×"]
    assert rows["no peers"][3:7] == ["—", "—", "+0.10 % / —", "—"]
    assert rows["50"][2:4] == ["55 → 5, —, 5", "1.40, —, 4.19"]
