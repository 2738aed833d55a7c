"""topology_kept on non-manifold inputs, whose partition checks leave issues they cannot judge:
True when every component kept its invariants, False (and said so on the command line and in the
batch report) when the output lost components. A book of three pages plus four spheres: fast mode
at ratio 0.1 keeps them all, also with its repair rounds capped at 3 (it lost the spheres then, until a
pass left broken was redone from the whole mesh)."""

import functools
import json

import numpy as np

import cli
import meshgen
from broken_engine import reporting_lost_components
from reference import invariants
from topstoc.core.api.io import MeshData, write_mesh
from topstoc.core.api.mesh import Mesh
from topstoc.core.cli import main as cli_main
from topstoc.core.support.native import engine

topstoc = functools.partial(cli.run, "decimate", timeout=120)


def book_and_spheres():
    return meshgen.disjoint(meshgen.subdivide(*meshgen.book(3), 3), *[meshgen.icosphere(1)] * 4)


def components_and_euler(triangles):
    """(components, V - E + F), counted by tests/reference.py independently of the engine."""
    t = np.asarray(triangles, dtype=np.int64)
    per_component = invariants(int(t.max()) + 1, t)
    return len(per_component), sum(chi for chi, *_ in per_component)


def test_quality_keeps_the_topology_the_partition_checks_cannot_judge():
    vertices, triangles = book_and_spheres()
    result = Mesh(vertices, triangles).decimate(0.1, mode="quality", seed=1)
    assert result.stats.issues_left > 0 and result.stats.check_violations == 0  # the checks' blind spot
    assert components_and_euler(result.triangles) == components_and_euler(triangles) == (5, 9)
    assert result.stats.invariants_kept and result.stats.topology_kept
    assert result.stats.topology_warning == ""


def test_fast_mode_keeps_the_spheres(tmp_path):
    # The repairs stall on the book's fins; the spheres left without a triangle are then split
    # (test_fast_components.py), so fast mode keeps every component too.
    vertices, triangles = book_and_spheres()
    result = Mesh(vertices, triangles).decimate(0.1, mode="fast", seed=1)
    assert components_and_euler(result.triangles) == components_and_euler(triangles) == (5, 9)
    assert result.stats.topology_kept is True and result.stats.output_check["lost_components"] == 0
    source = tmp_path / "book.obj"
    write_mesh(source, MeshData(vertices=np.asarray(vertices, float), triangles=np.asarray(triangles)))
    fast = topstoc(source, tmp_path / "fast.obj", "--ratio", 0.1, "--mode", "fast", "--seed", 1)
    assert fast.returncode == 0 and "topology" not in fast.stderr


def test_fast_mode_with_its_repairs_capped_keeps_the_spheres():
    # 3 rounds leave the spheres lost: that pass is redone as collapses from the whole mesh
    vertices, triangles = book_and_spheres()
    result = Mesh(vertices, triangles).decimate(0.1, mode="fast", seed=1, max_repair_rounds=3)
    assert components_and_euler(result.triangles) == (5, 9)
    assert result.stats.topology_kept is True and result.stats.topology_warning == ""
    assert result.stats.output_vertices <= result.stats.target_vertices  # and the target is met
    assert np.array_equal(result.vertices, np.asarray(vertices, float)[result.kept])  # input positions


def test_the_cli_warns_when_the_topology_is_not_kept(tmp_path, monkeypatch, capsys):
    reporting_lost_components(monkeypatch, engine)
    vertices, triangles = book_and_spheres()
    result = Mesh(vertices, triangles).decimate(0.1, mode="fast", seed=1)
    assert result.stats.topology_kept is False
    warning = result.stats.topology_warning
    assert warning.startswith("topology NOT kept: ") and warning.endswith(", 2 lost components")
    source = tmp_path / "book.obj"
    write_mesh(source, MeshData(vertices=np.asarray(vertices, float), triangles=np.asarray(triangles)))
    assert cli_main(["decimate", str(source), str(tmp_path / "fast.obj"), "--ratio", "0.1", "--mode", "fast",
                     "--seed", "1"]) == 0
    assert (tmp_path / "fast.obj").exists()  # written, and never silently
    assert f"fast.obj: {warning}" in capsys.readouterr().err


def test_batch_reports_the_topology_not_kept(tmp_path, monkeypatch, capsys):
    reporting_lost_components(monkeypatch, engine)
    vertices, triangles = book_and_spheres()
    source = tmp_path / "book.obj"
    write_mesh(source, MeshData(vertices=np.asarray(vertices, float), triangles=np.asarray(triangles)))
    out = tmp_path / "out"
    assert cli_main(["batch", "--input", str(source), "--output", str(out), "--ratio", "0.1", "--mode", "fast",
                     "--seed", "1", "--workers", "0", "--progress", "lines"]) == 0
    stdout = capsys.readouterr().out
    line = next(text for text in stdout.splitlines() if "book.obj:" in text)
    assert "topology NOT kept: " in line and "lost components" in line
    assert "1 done (1 did not keep the topology)" in stdout
    lod = json.loads((out / "topstoc-report.json").read_text())["results"][0]["lods"][0]
    assert lod["topology_kept"] is False and lod["topology_warning"].startswith("topology NOT kept: ")
