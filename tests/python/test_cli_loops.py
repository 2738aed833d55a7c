"""The ``loops`` command line (docs/design.md §6), run as a subprocess like a user would."""

import functools
import gzip
import pathlib

import numpy as np

import cli
import homology_check as hc
from meshgen import genus_slab, torus
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"

topstoc = functools.partial(cli.run, "loops")
run_json = functools.partial(cli.run_json, "loops")
assert_one_error_line = functools.partial(cli.assert_one_error_line, "loops")


def test_json_lists_genus_handles_and_tunnels_in_file_ids():
    source = DATA / "genus_positive" / "cgal_double-torus-example.off"
    doc = run_json(source)
    data = read_mesh(source)
    (component,) = doc["components"]
    assert component["genus"] == 2 and component["status"] == "ok"
    assert len(component["handles"]) == len(component["tunnels"]) == 2
    for loop in component["handles"] + component["tunnels"]:
        assert hc.is_simple_edge_cycle(loop, data.triangles)
    lengths = [entry["length"] for entry in component["handle_loops"] + component["tunnel_loops"]]
    expected = [hc.loop_length(data.vertices, loop) for loop in component["handles"] + component["tunnels"]]
    np.testing.assert_allclose(lengths, expected)
    assert doc["input"]["vertices"] == len(data.vertices)
    assert doc["seconds"]["total"] >= doc["seconds"]["tetrahedralize"] > 0


def test_vertex_ids_follow_the_file_order_and_stl_welding(tmp_path):
    vertices, triangles = torus(24, 12)
    # Shuffle the file's vertex order: the loops must name the file's ids.
    order = np.random.default_rng(3).permutation(len(vertices))
    inverse = np.argsort(order)
    shuffled = MeshData(vertices=vertices[order], triangles=inverse[triangles].astype(np.int32))
    path = tmp_path / "torus.ply.gz"
    write_mesh(path, shuffled)
    doc = run_json(path)
    (component,) = doc["components"]
    (handle,), (tunnel,) = component["handles"], component["tunnels"]
    assert hc.is_simple_edge_cycle(handle, shuffled.triangles)
    original_ids = order[np.array(tunnel)]
    radius = np.hypot(vertices[original_ids, 0], vertices[original_ids, 1])
    np.testing.assert_allclose(radius, 1.0 - 0.35)  # the inner equator
    stl = tmp_path / "torus.stl"
    write_mesh(stl, MeshData(vertices=vertices, triangles=triangles))
    welded = read_mesh(stl)
    doc = run_json(stl)
    for loop in doc["components"][0]["handles"] + doc["components"][0]["tunnels"]:
        assert hc.is_simple_edge_cycle(loop, welded.triangles)


def test_text_output_and_routes(tmp_path):
    vertices, triangles = genus_slab(3)
    path = tmp_path / "slab.obj"
    write_mesh(path, MeshData(vertices=vertices, triangles=triangles))
    done = topstoc(path)
    assert done.returncode == 0, done.stderr
    assert "genus 3, full route" in done.stdout
    assert done.stdout.count("  handle ") == 3 and done.stdout.count("  tunnel ") == 3
    coarse = run_json(path, "--coarse-vertices", 60)
    assert coarse["components"][0]["route"] == "coarse"
    assert len(coarse["components"][0]["tunnels"]) == 3
    edges = run_json(path, "--metric", "edges", "--no-shorten")
    assert len(edges["components"][0]["handles"]) == 3


def test_open_components_are_reported():
    doc = run_json(DATA / "open_boundary" / "cgal_mushroom.off")
    assert [c["status"] for c in doc["components"]] == ["open"]
    assert doc["components"][0]["handles"] == []


def test_errors_are_one_line(tmp_path):
    assert_one_error_line(topstoc(DATA / "nonmanifold_degenerate" / "dragon_vrip_res4.ply.gz"),
                          "non-manifold", "three or more triangles")
    vertices, triangles = torus(24, 12, major=0.3, minor=0.5)
    path = tmp_path / "spindle.off"
    write_mesh(path, MeshData(vertices=vertices, triangles=triangles))
    assert_one_error_line(topstoc(path), "intersects itself", "triangles (")
    assert_one_error_line(topstoc(tmp_path / "missing.obj"), "missing.obj")
    assert_one_error_line(topstoc(DATA / "genus_positive" / "cgal_eight.off", "--coarse-vertices", 0),
                          "--coarse-vertices")
    broken = tmp_path / "broken.off.gz"
    broken.write_bytes(gzip.compress(b"OFF\n3 1 0\n0 0 0\n1 0 0\n"))
    done = topstoc(broken)
    assert done.returncode == 1 and done.stdout == ""


def test_a_refused_component_is_one_line_and_the_others_are_searched(tmp_path):
    """A non-manifold component beside a genus-2 block used to stop the command with an error:
    now it is one line naming it (in the file's ids) and the block's loops are listed."""
    import cleanup_meshes
    from meshgen import tetrahedra_sharing_edge

    block, block_triangles = cleanup_meshes.block_with_arches(2, 0, jitter=0.05, seed=5)
    fin, fin_triangles = tetrahedra_sharing_edge()  # four triangles on one edge
    n = len(block)
    path = tmp_path / "two.off"
    write_mesh(path, MeshData(vertices=np.vstack([block, fin + [0.0, 0.0, 20.0]]),
                              triangles=np.vstack([block_triangles, fin_triangles + n]).astype(np.int32)))
    done = topstoc(path)
    assert done.returncode == 0, done.stderr
    refused = [line for line in done.stdout.splitlines() if line.startswith("component 1")]
    assert len(refused) == 1 and "refused" in refused[0] and "non-manifold" in refused[0], done.stdout
    assert f"edge {n}-{n + 1}" in refused[0]  # the file's vertex ids, not the component's own
    doc = run_json(path)
    assert [c["status"] for c in doc["components"]] == ["ok", "refused"]
    assert doc["components"][0]["genus"] == 2 and len(doc["components"][0]["handles"]) == 2
    for loop in doc["components"][0]["handles"] + doc["components"][0]["tunnels"]:
        assert hc.is_simple_edge_cycle(loop, block_triangles)
