"""``python3 -m topstoc topology IN`` (docs/design.md §6): JSON keys and values, text report, errors."""

import functools
import json

import pytest

import cli

pytest.importorskip("topstoc.core.api.io")
from topstoc.core.api.io import read_mesh  # noqa: E402
from topstoc.core.api.topology import topology  # noqa: E402

run_cli = functools.partial(cli.run, "topology", timeout=120)


def test_json_report_matches_the_api(data_dir):
    path = data_dir / "genus_positive" / "cgal_double-torus-example.off"
    done = run_cli(path, "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    data = read_mesh(str(path))
    info = topology(data.vertices, data.triangles)
    assert report["betti"] == list(info.betti) == [1, 4, 1]
    (c,) = report["components"]
    assert {"vertices", "edges", "faces", "euler", "betti", "closed", "orientable", "manifold", "genus",
            "boundary_loops"} <= c.keys()
    assert (c["vertices"], c["faces"], c["euler"], c["genus"], c["closed"], c["orientable"], c["manifold"]) == \
        (231, 466, -2, 2, True, True, True)
    assert c["boundary_loops"] == [] and report["seconds"] >= 0
    assert "generators" not in report


def test_json_boundary_loops_and_generators(data_dir):
    report = json.loads(run_cli(data_dir / "open_boundary" / "cgal_mushroom.off", "--json").stdout)
    (c,) = report["components"]
    assert (c["genus"], c["closed"], len(c["boundary_loops"])) == (0, False, 1)
    assert len(c["boundary_loops"][0]) == 64  # the README's 64 boundary edges form one loop
    report = json.loads(run_cli(data_dir / "genus_positive" / "cgal_3torus.off", "--json", "--generators").stdout)
    (g,) = report["generators"]
    assert g["genus"] == 3 and len(g["edges"]) == 6 == len(g["loops"])
    assert all(loop[:2] == edge for loop, edge in zip(g["loops"], g["edges"]))


def test_text_report(data_dir):
    done = run_cli(data_dir / "genus_positive" / "cgal_turbine.off", "--generators")
    assert done.returncode == 0, done.stderr
    assert "betti 1/22/1" in done.stdout
    assert "component 0: genus 11, closed, orientable" in done.stdout
    assert "component 0: 22 generator edges" in done.stdout


def test_errors_are_one_line(tmp_path):
    done = run_cli(tmp_path / "missing.off")
    assert done.returncode == 1 and done.stdout == ""
    assert len(done.stderr.strip().splitlines()) == 1 and "topstoc topology: error:" in done.stderr
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    done = run_cli(bad)
    assert done.returncode == 1 and len(done.stderr.strip().splitlines()) == 1
