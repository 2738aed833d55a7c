"""Screen-size targets (topstoc.core.batch.screen_size) and pruning small parts (topstoc.core.batch.prune),
checked against a pinhole camera, brute-force bounding spheres and the project's Hausdorff."""

import json
import math

import numpy as np
import pytest

import cli
import meshgen
from topstoc.core.batch.mesh_asset import decimate_mesh_file
from topstoc.core.api.hausdorff import hausdorff
from topstoc.core.api.io import MeshData, read_mesh, write_mesh
from topstoc.core.api.mesh import Mesh
from topstoc.core.batch.prune import prune_small_parts, triangle_parts
from topstoc.core.batch.screen_size import bounding_sphere, projected_pixels, screen_target


def test_projected_diameter_matches_a_pinhole_camera():
    """The silhouette of a sphere straight ahead, projected point by point: its height in pixels."""
    radius, distance, fov, rows = 1.7, 9.0, 50.0, 1440
    focal = (rows / 2) / math.tan(math.radians(fov) / 2)
    # Silhouette points: tangent cone from the camera at the origin to the sphere at (0, 0, distance).
    angle = math.asin(radius / distance)
    theta = np.linspace(0, 2 * np.pi, 721)
    directions = np.stack([np.sin(angle) * np.cos(theta), np.sin(angle) * np.sin(theta),
                           np.full_like(theta, np.cos(angle))], axis=1)
    y_pixels = focal * directions[:, 1] / directions[:, 2]
    assert projected_pixels(radius, distance, fov, rows) == pytest.approx(np.ptp(y_pixels), rel=1e-6)
    with pytest.raises(ValueError, match="must exceed the bounding-sphere radius"):
        projected_pixels(radius, 1.0, fov, rows)
    with pytest.raises(ValueError, match="fov must lie in"):
        projected_pixels(radius, distance, 180.0, rows)


def test_bounding_sphere_contains_every_vertex_and_scales():
    v, _ = meshgen.torus(16, 8)
    v = v * [3.0, 1.0, 0.5] + [10.0, -4.0, 2.0]
    centre, radius = bounding_sphere(v)
    distances = np.linalg.norm(v - centre, axis=1)
    assert distances.max() == pytest.approx(radius) and (distances <= radius + 1e-12).all()
    target = screen_target(v, pixels=400.0, pixel_error=2.0)
    assert target.world_per_pixel == pytest.approx(2 * radius / 400.0)
    assert target.max_error == pytest.approx(2.0 * 2 * radius / 400.0)
    assert target.to_pixels(target.max_error) == pytest.approx(2.0)
    # Seen from a distance, the same conversion goes through the projected diameter.
    far = screen_target(v, distance=50.0, fov_degrees=60.0, resolution=1080)
    assert far.pixels == pytest.approx(projected_pixels(radius, 50.0, 60.0, 1080))
    with pytest.raises(ValueError, match="exactly one"):
        screen_target(v, pixels=10.0, distance=5.0)


SETTINGS = {"target": "screen_pixels", "values": [300.0], "chain": False, "pixel_error": 1.0, "fov": 60.0,
            "resolution": 1080, "prune_pixels": 0.0, "lod_files": False, "format": None,
            "options": {"seed": 0, "adaptivity": 0.5, "density": "off", "placement": "subsample", "refine": 0},
            "objects": None}


def _torus_file(folder):
    v, f = meshgen.torus(64, 24)
    path = folder / "torus.ply"
    write_mesh(path, MeshData(vertices=v * 3.0 + [1.0, 2.0, 3.0], triangles=f))
    return path


@pytest.mark.parametrize("pixels", [40.0, 150.0])
def test_screen_target_error_within_the_pixel_bound(tmp_path, pixels):
    """Decimate for an object covering N pixels; measure the output against the input with the
    project's Hausdorff (denser sampling than the search's), in pixels by the brute-force sphere."""
    source = _torus_file(tmp_path)
    settings = dict(SETTINGS, values=[pixels])
    (tmp_path / "out").mkdir()
    entry = decimate_mesh_file(str(source), str(tmp_path / "out"), settings)
    original, written = read_mesh(source), read_mesh(entry["output"])
    centre = 0.5 * (original.vertices.min(axis=0) + original.vertices.max(axis=0))
    radius = np.linalg.norm(original.vertices - centre, axis=1).max()
    measured = hausdorff(original, written, samples=400_000, percentile=0).symmetric.max
    error_pixels = measured / (2 * radius / pixels)
    assert error_pixels <= 1.0 * 1.01, error_pixels   # 1 px, with 1 % for the denser sampling
    assert written.num_vertices < original.num_vertices
    [lod] = entry["lods"]
    assert lod["hausdorff_pixels"] <= 1.0 and lod["screen"]["pixels"] == pixels
    # the report's bounded estimate: a distance attained (below the denser measurement, within
    # 10 % of it) and a guaranteed upper bound (above it)
    assert error_pixels * 0.9 <= lod["hausdorff_pixels"] <= error_pixels * 1.01 <= lod["hausdorff_upper_pixels"] * 1.01


def test_smaller_screen_fewer_vertices_lod_chain(tmp_path):
    source = _torus_file(tmp_path)
    settings = dict(SETTINGS, values=[400.0, 100.0, 25.0], chain=True)
    (tmp_path / "out").mkdir()
    entry = decimate_mesh_file(str(source), str(tmp_path / "out"), settings)
    names = [p.split("/")[-1] for p in entry["outputs"]]
    assert names == ["torus_LOD0.ply", "torus_LOD1.ply", "torus_LOD2.ply"]
    counts = [read_mesh(p).num_vertices for p in entry["outputs"]]
    assert counts == [lod["vertices"] for lod in entry["lods"]]
    assert counts[0] > counts[1] > counts[2]
    assert all(lod["hausdorff_pixels"] <= 1.0 for lod in entry["lods"])


def test_triangle_parts_agree_with_scipy():
    csgraph = pytest.importorskip("scipy.sparse.csgraph")
    import scipy.sparse as sparse

    rng = np.random.default_rng(3)
    n = 3000
    t = rng.integers(0, n, size=(1200, 3))
    parts = triangle_parts(n, t)
    graph = sparse.coo_matrix((np.ones(2 * len(t)), (np.r_[t[:, 0], t[:, 1]], np.r_[t[:, 1], t[:, 2]])),
                              shape=(n, n))
    _, labels = csgraph.connected_components(graph, directed=False)
    pairs = set(zip(parts.tolist(), labels[t[:, 0]].tolist()))
    assert len(pairs) == len(set(parts.tolist())) == len(set(labels[t[:, 0]].tolist()))


def test_pruning_drops_small_parts_and_reports_them(tmp_path):
    big = meshgen.icosphere(3)
    small = [(v * 0.02, f) for v, f in [meshgen.icosphere(1)] * 3]
    v, f = meshgen.disjoint(big, *small)
    mesh = Mesh(v, f)
    result = mesh.decimate(ratio=0.5, seed=1, mode="fast")  # input positions: kept maps checkable
    pruned, report = prune_small_parts(result, 0.1)
    assert report.parts == 4 and report.removed_parts == 3
    assert report.removed_triangles == result.num_triangles - pruned.num_triangles
    assert report.removed_vertices == result.num_vertices - pruned.num_vertices
    # What is left is the big sphere's decimation, unchanged, with consistent maps.
    assert len(triangle_parts(pruned.num_vertices, pruned.triangles)) == pruned.num_triangles
    np.testing.assert_array_equal(pruned.vertices, np.asarray(result.vertices)[:pruned.num_vertices])
    np.testing.assert_array_equal(np.asarray(pruned.vertices), v[np.asarray(pruned.kept)])
    assert len(pruned.face_source) == len(pruned.corner_source) == pruned.num_triangles
    same, report = prune_small_parts(result, 0.001)
    assert same is result and report.removed_parts == 0


@pytest.mark.heavy
def test_prune_option_through_the_batch(tmp_path):
    big = meshgen.icosphere(2)
    v, f = meshgen.disjoint(big, (meshgen.icosphere(1)[0] * 0.01, meshgen.icosphere(1)[1]))
    source = tmp_path / "parts.ply"
    write_mesh(source, MeshData(vertices=v, triangles=f))
    out = tmp_path / "out"
    done = cli.run("batch", "--input", source, "--output", out, "--screen-pixels", 100, "--prune-pixels", 2,
                   "--workers", 0, "--progress", "lines")
    assert done.returncode == 0, done.stderr
    [entry] = json.loads((out / "topstoc-report.json").read_text())["results"]
    [lod] = entry["lods"]
    assert lod["pruned"]["removed_parts"] == 1 and lod["pruned"]["parts"] == 2
    written = read_mesh(out / "parts.ply")
    assert len(set(triangle_parts(written.num_vertices, written.triangles).tolist())) == 1
    gap = (v[: len(big[0]), 0].max() + v[len(big[0]):, 0].min()) / 2
    assert written.vertices[:, 0].max() < gap  # the small sphere, beyond the gap, is gone
    done = cli.run("batch", "--input", source, "--output", out, "--ratio", 0.5, "--prune-pixels", 2, "--workers", 0)
    assert done.returncode == 1 and "--prune-pixels needs a screen target" in done.stderr
