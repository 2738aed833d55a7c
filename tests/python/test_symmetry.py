"""Mirror-symmetric decimation: a symmetric input gives a symmetric output, with the topology,
the control points and reproducibility kept. Topology is checked with tests/reference.py."""

import pathlib

import numpy as np
import pytest

import meshgen  # noqa: F401  (tests/ on the path)
import reference
from topstoc.core import Mesh, read_mesh
from topstoc.core.api.symmetry import decimate_symmetric, mirror_partners

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
SUZANNE = DATA / "open_boundary/kivy_suzanne_monkey.obj"


def suzanne():
    """Suzanne with her mirror plane moved onto x = 0 (the file has it at x = -0.0149)."""
    data = read_mesh(SUZANNE)
    v = data.vertices.copy()
    v[:, 0] -= 0.5 * (v[:, 0].min() + v[:, 0].max())
    return Mesh(v, data.triangles)


def brute_force_partners(vertices, axis, tol):
    """Partner of every vertex by comparing every pair (the reference)."""
    mirrored = vertices.copy()
    mirrored[:, axis] *= -1
    distance = np.linalg.norm(vertices[None, :, :] - mirrored[:, None, :], axis=2)
    nearest = distance.argmin(axis=1)
    return np.where(distance[np.arange(len(vertices)), nearest] <= tol, nearest, -1)


def mirror_gap(vertices, axis):
    """Largest distance from a mirrored output vertex to the nearest output vertex."""
    mirrored = vertices.copy()
    mirrored[:, axis] *= -1
    distance = np.linalg.norm(vertices[None, :, :] - mirrored[:, None, :], axis=2)
    return distance.min(axis=1).max()


def test_partners_match_brute_force_on_suzanne():
    mesh = suzanne()
    v = mesh.vertices
    tol = 1e-5 * mesh.diagonal
    expected = brute_force_partners(v, 0, tol)
    np.testing.assert_array_equal(mirror_partners(v, "X"), expected)
    assert (expected >= 0).mean() > 0.99  # Suzanne is symmetric about X


@pytest.mark.parametrize("axis", ["X", "Y", "Z"])
def test_partners_on_a_mirrored_random_cloud(axis):
    rng = np.random.default_rng(3)
    half = rng.uniform(0.01, 1, size=(300, 3))
    index = "XYZ".index(axis)
    other = half.copy()
    other[:, index] *= -1
    cloud = np.vstack([half, other, rng.uniform(-1, 1, size=(20, 3))])  # 20 without partner (almost surely)
    partner = mirror_partners(cloud, axis)
    np.testing.assert_array_equal(partner, brute_force_partners(cloud, index, 1e-5 * np.sqrt(12)))
    np.testing.assert_array_equal(partner[:300], np.arange(300, 600))


@pytest.mark.parametrize("placement", ["subsample", "filtered"])
@pytest.mark.parametrize("seed", range(4))
def test_symmetric_input_gives_symmetric_output(placement, seed):
    mesh = suzanne()
    expected = reference.invariants(mesh.num_vertices, mesh.triangles)
    plain = mesh.decimate(ratio=0.2, seed=seed, placement=placement)
    result = decimate_symmetric(mesh, "X", ratio=0.2, seed=seed, placement=placement)
    assert reference.invariants(result.num_vertices, result.triangles) == expected
    assert result.stats.topology_kept
    assert mirror_gap(result.vertices, 0) <= 1e-5 * mesh.diagonal
    if placement == "filtered":  # averaged with the partner's mirror image: still near its cluster
        kept = np.asarray(result.kept)
        moved = np.linalg.norm(result.vertices - mesh.vertices[kept], axis=1)
        assert np.median(moved) < 0.01 * mesh.diagonal
    # the plain result is not symmetric, so the test can tell
    assert mirror_gap(plain.vertices, 0) > 1e-3 * mesh.diagonal
    # about the same size as the plain decimation
    assert abs(result.num_vertices - plain.num_vertices) <= 0.15 * plain.num_vertices


def test_symmetric_output_is_reproducible_and_keeps_control_points():
    mesh = suzanne()
    guidance = np.zeros(mesh.num_vertices)
    guidance[[5, 77]] = 1.0  # control points (u = 1) on either side
    first = decimate_symmetric(mesh, "X", ratio=0.1, seed=2, guidance=guidance)
    again = decimate_symmetric(mesh, "X", ratio=0.1, seed=2, guidance=guidance)
    np.testing.assert_array_equal(first.vertices, again.vertices)
    np.testing.assert_array_equal(first.triangles, again.triangles)
    partner = mirror_partners(mesh.vertices, "X")
    kept = set(first.kept.tolist())
    for v in (5, 77):
        assert v in kept and (partner[v] < 0 or partner[v] in kept)
    replay = mesh.decimate_with_samples(first.samples)
    np.testing.assert_array_equal(replay.vertices, first.vertices)


def test_bad_axis_is_refused():
    with pytest.raises(ValueError, match="symmetry axis"):
        mirror_partners(np.zeros((3, 3)), "W")


# -- the command line and the batch ------------------------------------------------------------

def _write_suzanne(path):
    from topstoc.core.api.io import MeshData, write_mesh

    mesh = suzanne()
    write_mesh(path, MeshData(vertices=mesh.vertices, triangles=mesh.triangles))
    return mesh


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_cli_symmetry_gives_a_mirror_symmetric_file(tmp_path, mode):
    import cli

    mesh = _write_suzanne(tmp_path / "suzanne.ply")
    report = cli.run_json("decimate", tmp_path / "suzanne.ply", tmp_path / "sym.ply", "--ratio", 0.2,
                          "--symmetry", "x", "--mode", mode, "--seed", 3)
    assert report["symmetry"] == "X"
    out = read_mesh(tmp_path / "sym.ply")
    assert out.num_vertices == report["output"]["vertices"]
    assert mirror_gap(out.vertices, 0) <= 1e-5 * mesh.diagonal
    assert reference.invariants(out.num_vertices, out.triangles) == \
        reference.invariants(mesh.num_vertices, mesh.triangles)
    # the same call without --symmetry is not symmetric, so the check can tell
    plain = cli.run_json("decimate", tmp_path / "suzanne.ply", tmp_path / "plain.ply", "--ratio", 0.2,
                         "--mode", mode, "--seed", 3)
    assert plain["symmetry"] is None
    assert mirror_gap(read_mesh(tmp_path / "plain.ply").vertices, 0) > 1e-3 * mesh.diagonal


def test_cli_symmetry_refuses_an_unknown_axis(tmp_path):
    import cli

    _write_suzanne(tmp_path / "suzanne.ply")
    done = cli.run("decimate", tmp_path / "suzanne.ply", tmp_path / "out.ply", "--ratio", 0.2, "--symmetry", "w")
    assert done.returncode != 0 and "--symmetry" in done.stderr and not (tmp_path / "out.ply").exists()


def test_batch_symmetry_gives_mirror_symmetric_lods(tmp_path):
    import json

    import cli

    (tmp_path / "in").mkdir()
    mesh = _write_suzanne(tmp_path / "in" / "suzanne.obj")
    done = cli.run("batch", "--input", tmp_path / "in", "--output", tmp_path / "out", "--ratio", 0.3, 0.1,
                   "--symmetry", "X", "--workers", 0)
    assert done.returncode == 0, done.stderr
    [entry] = json.loads((tmp_path / "out" / "topstoc-report.json").read_text())["results"]
    assert [lod["symmetry"] for lod in entry["lods"]] == ["X", "X"]
    counts = []
    for lod in entry["lods"]:
        out = read_mesh(lod["output"])
        counts.append(out.num_vertices)
        assert mirror_gap(out.vertices, 0) <= 1e-5 * mesh.diagonal, lod["output"]
    assert counts[0] > counts[1]
    # the settings digest tells the symmetric run from a plain one: a rerun without --symmetry redoes it
    again = cli.run("batch", "--input", tmp_path / "in", "--output", tmp_path / "out", "--ratio", 0.3, 0.1,
                    "--workers", 0)
    assert again.returncode == 0, again.stderr
    [entry] = json.loads((tmp_path / "out" / "topstoc-report.json").read_text())["results"]
    assert [lod["symmetry"] for lod in entry["lods"]] == [None, None]
    assert mirror_gap(read_mesh(entry["lods"][1]["output"]).vertices, 0) > 1e-3 * mesh.diagonal
