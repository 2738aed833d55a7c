"""``python3 -m topstoc fill-holes`` and ``remove-handle`` (docs/design.md §6)."""

import json

import numpy as np
import pytest

import meshgen
import reference as ref
from cli import run as topstoc

io = pytest.importorskip("topstoc.core.api.io", reason="file I/O (topstoc.core.api.io) is not in this build")
pytest.importorskip("topstoc.core.api.topology", reason="topstoc.core.api.topology is not in this build")


def genus_of(vertices, triangles):
    (chi, boundary, manifold, orientable), = ref.invariants(len(vertices), triangles)
    assert manifold and orientable
    return ref.euler_genus(chi, boundary), boundary


def test_fill_holes_writes_a_closed_mesh_and_reports_its_topology(data_dir, tmp_path):
    out = tmp_path / "mushroom.obj"
    run = topstoc("fill-holes", data_dir / "open_boundary" / "cgal_mushroom.off", out, "--json")
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout)
    assert report["betti"] == [1, 0, 1]
    (component,) = report["components"]
    assert component["closed"] and component["genus"] == 0
    assert report["edit"]["holes_filled"] == 1 and report["edit"]["methods"] == {"planar": 1}
    written = io.read_mesh(out)
    assert genus_of(written.vertices, written.triangles) == (0, 0)


def test_fill_holes_selection_and_errors(data_dir, tmp_path):
    source = data_dir / "open_boundary" / "cgal_elephant-with-holes.off"
    run = topstoc("fill-holes", source, tmp_path / "a.off", "--max-edges", "6", "--json")
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout)
    assert report["edit"]["holes_filled"] == 48  # the hexagonal holes
    assert len(report["components"][0]["boundary_loops"]) == 106 - 48
    assert all(hole["edges"] == 6 and hole["method"] == "planar" for hole in report["edit"]["filled"])
    bad = topstoc("fill-holes", source, tmp_path / "b.off", "--holes", "500")
    assert bad.returncode == 1 and "out of range" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1
    bad = topstoc("fill-holes", source, tmp_path / "b.off", "--holes", "x")
    assert bad.returncode == 1 and "comma-separated" in bad.stderr


def test_attributes_survive_filling(tmp_path):
    vertices, triangles = meshgen.grid(6, 6)
    centroids = vertices[triangles].mean(axis=1)
    keep = np.hypot(centroids[:, 0] - 3, centroids[:, 1] - 3) > 1.2
    triangles = triangles[keep]
    uvs = vertices[triangles][:, :, :2] / 6.0
    material = (centroids[keep, 0] > 3).astype(np.int32)
    data = io.MeshData(vertices=vertices, triangles=triangles, corner_uvs=uvs, triangle_material=material,
                       material_names=["left", "right"])
    source, out = tmp_path / "holed.obj", tmp_path / "filled.obj"
    io.write_mesh(source, data)
    run = topstoc("fill-holes", source, out, "--holes", "1")
    assert run.returncode == 0, run.stderr
    written = io.read_mesh(out)
    assert written.num_triangles > len(triangles)
    assert written.corner_uvs is not None and not np.isnan(written.corner_uvs).any()
    # Every UV still equals the vertex position / 6 (the hole's border corners took a neighbour's UV).
    assert np.allclose(written.corner_uvs, written.vertices[written.triangles][:, :, :2] / 6.0)
    assert set(written.triangle_material) <= {0, 1}


def test_remove_handle_by_loop_and_by_index(data_dir, tmp_path):
    vertices, triangles = meshgen.torus(24, 12)
    source = tmp_path / "torus.ply"
    io.write_mesh(source, io.MeshData(vertices=vertices, triangles=triangles))
    run = topstoc("remove-handle", source, tmp_path / "sphere.ply", "--loop", ",".join(map(str, range(12))), "--json")
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout)
    assert report["betti"] == [1, 0, 1] and report["edit"]["loop_kind"] == "given"
    written = io.read_mesh(tmp_path / "sphere.ply")
    assert genus_of(written.vertices, written.triangles) == (0, 0)
    assert np.allclose(written.vertices[12:len(vertices)], vertices[12:])  # off the loop: unchanged
    bad = topstoc("remove-handle", source, tmp_path / "x.ply", "--loop", "0,1,40")
    assert bad.returncode == 1 and "not joined by an edge" in bad.stderr

    pytest.importorskip("topstoc.core.api.loops", reason="handle loops (topstoc.core.api.loops) are not in this build")
    double = data_dir / "genus_positive" / "cgal_double-torus-example.off"
    for kind in ([], ["--tunnel"]):
        run = topstoc("remove-handle", double, tmp_path / "single.off", "--index", "1", *kind, "--json")
        assert run.returncode == 0, run.stderr
        report = json.loads(run.stdout)
        assert report["components"][0]["genus"] == 1 and report["components"][0]["closed"]
    bad = topstoc("remove-handle", double, tmp_path / "x.off", "--index", "2")
    assert bad.returncode == 1 and "out of range" in bad.stderr
