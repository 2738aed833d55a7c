"""The ``decimate`` command line (docs/design.md §6), run as a subprocess like a user would."""

import functools
import inspect
import json
import pathlib

import numpy as np
import pytest

import cli
from meshgen import torus
from topstoc.core.api.decimate import decimate as core_decimate
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"

topstoc = functools.partial(cli.run, "decimate", timeout=120)
run_json = functools.partial(cli.run_json, "decimate")
assert_one_error_line = functools.partial(cli.assert_one_error_line, "decimate")


def run_json_warned(*args):
    """The --json report of a run that must succeed, silent but for the topology warning exactly
    when the report says the topology was not kept."""
    done = topstoc(*args, "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    warned = done.stderr.startswith("topstoc: warning: ") and "topology NOT kept: " in done.stderr
    assert (done.stderr == "") == report["topology_kept"] and (report["topology_kept"] or warned), done.stderr
    return report


def test_json_report_matches_the_files(tmp_path):
    source = DATA / "genus_positive" / "cgal_elephant.off"
    out = tmp_path / "elephant.ply"
    report = run_json(source, out, "--vertices", 500, "--seed", 3, "--mode", "fast")
    original, written = read_mesh(source), read_mesh(out)
    assert report["input"]["vertices"] == original.num_vertices == 2775
    assert report["input"]["triangles"] == original.num_triangles == 5558
    assert report["output"]["vertices"] == written.num_vertices
    assert report["output"]["triangles"] == written.num_triangles
    assert abs(written.num_vertices - 500) <= 5 + report["repairs"]
    assert report["seconds"] > 0 and isinstance(report["repairs"], int)
    assert report["topology_kept"] is True
    # Output vertices are input vertices; a closed genus-3 surface keeps chi = -4.
    original_rows = {tuple(v) for v in original.vertices}
    assert all(tuple(v) in original_rows for v in written.vertices)
    edges = np.unique(np.sort(written.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    assert written.num_vertices - len(edges) + written.num_triangles == -4


def test_triangle_and_ratio_targets(tmp_path):
    source = DATA / "genus0" / "cgal_fandisk.off"
    by_triangles = run_json(source, tmp_path / "a.obj", "--triangles", 2000)
    assert abs(by_triangles["output"]["triangles"] - 2000) <= 0.05 * 2000
    by_ratio = run_json(source, tmp_path / "b.off.gz", "--ratio", 0.1, "--density", "adaptive", "--adaptivity", 0.8)
    assert read_mesh(tmp_path / "b.off.gz").num_vertices == by_ratio["output"]["vertices"]
    assert abs(by_ratio["output"]["vertices"] - 648) <= 0.1 * 648


def test_same_seed_same_file_other_seed_other_file(tmp_path):
    source = DATA / "genus_positive" / "cgal_knot1.off"
    # (fast mode: in the quality mode at 20 % the stochastic pass keeps every vertex, so the
    # seed does not matter there)
    for name, seed in (("a.ply", 7), ("b.ply", 7), ("c.ply", 8)):
        run_json(source, tmp_path / name, "--ratio", 0.2, "--seed", seed, "--mode", "fast")
    assert (tmp_path / "a.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()
    assert (tmp_path / "a.ply").read_bytes() != (tmp_path / "c.ply").read_bytes()


@pytest.mark.parametrize("extra", [("--mode", "fast"), ("--refine", 6), ()], ids=["plain", "refined", "quality"])
def test_uvs_and_materials_survive(tmp_path, extra):
    source = DATA / "uv_materials" / "spider" / "spider.obj"
    report = run_json_warned(source, tmp_path / "spider.obj", "--ratio", 0.4, *extra)
    original, written = read_mesh(source), read_mesh(tmp_path / "spider.obj")
    assert report["input"]["uv_seam_edges"] > 0
    # the spider's vn lines are not written (shading follows the decimated shape): reported
    assert report["output"]["dropped_attributes"] == ["normals"]
    assert b"\nvn " in source.read_bytes() and b"\nvn " not in (tmp_path / "spider.obj").read_bytes()
    # every mode collapses here: fast mode too, as the spider's inconsistently oriented
    # components stall its first pass, and its collapses keep input positions (checked below)
    assert report["refine"]["vertices"] > 0 and report["refine"]["collapses"] > 0
    assert report["refine"]["mode"] == ("fast" if extra == ("--mode", "fast") else "quality")
    to_ply = run_json_warned(source, tmp_path / "spider.ply", "--ratio", 0.4, *extra)
    assert to_ply["output"]["dropped_attributes"] == ["triangle_material", "normals"]
    assert written.corner_uvs is not None and written.triangle_material is not None
    assert set(written.material_names) <= set(original.material_names)
    # Every output corner is an input corner: same position, same UV, same material; in the
    # quality mode, free vertices move (optimal placement), so every corner of a vertex on a
    # UV seam or material border is.
    corners = {(tuple(original.vertices[v]), tuple(original.corner_uvs[t, c]),
                original.material_names[original.triangle_material[t]])
               for t, tri in enumerate(original.triangles) for c, v in enumerate(tri)}
    attributes = {}
    for t, tri in enumerate(written.triangles):
        for c, v in enumerate(tri):
            attributes.setdefault(v, set()).add((tuple(written.corner_uvs[t, c]), written.triangle_material[t]))
    on_border = {v for v, values in attributes.items() if len(values) > 1}
    assert len(on_border) > 20
    for t, tri in enumerate(written.triangles):
        for c, v in enumerate(tri):
            if extra != ("--mode", "fast") and v not in on_border:
                continue
            key = (tuple(written.vertices[v]), tuple(written.corner_uvs[t, c]),
                   written.material_names[written.triangle_material[t]])
            assert key in corners, (t, c)
    # the .mtl is copied beside the output (another folder) and mtllib names the copy
    assert written.material_libraries == ["spider.mtl"]
    assert (tmp_path / "spider.mtl").read_bytes() == (source.parent / "spider.mtl").read_bytes()


def test_vertex_colours_survive(tmp_path):
    vertices, triangles = torus(40, 20)
    colors = np.round(np.random.default_rng(1).random((len(vertices), 3)) * 255) / 255
    write_mesh(tmp_path / "torus.ply", MeshData(vertices=vertices, triangles=triangles, vertex_colors=colors))
    run_json(tmp_path / "torus.ply", tmp_path / "small.ply", "--ratio", 0.25, "--mode", "fast")
    written = read_mesh(tmp_path / "small.ply")
    index = {tuple(v): i for i, v in enumerate(vertices)}
    source = np.array([index[tuple(v)] for v in written.vertices])
    np.testing.assert_array_equal(written.vertex_colors, colors[source])


def test_guidance_keeps_control_points(tmp_path):
    source = DATA / "genus_positive" / "cgal_eight.off"
    u = np.zeros(315)
    control = np.arange(0, 315, 10)
    u[control] = 1.0
    np.save(tmp_path / "u.npy", u)
    report = run_json(source, tmp_path / "out.off", "--ratio", 0.1, "--guidance", tmp_path / "u.npy")
    assert report["guided"] is True
    original, written = read_mesh(source), read_mesh(tmp_path / "out.off")
    kept = {tuple(v) for v in written.vertices}
    assert all(tuple(original.vertices[v]) in kept for v in control)


def test_guidance_of_the_wrong_length(tmp_path):
    np.save(tmp_path / "u.npy", np.zeros(100))
    done = topstoc(DATA / "genus_positive" / "cgal_eight.off", tmp_path / "out.off", "--ratio", 0.1,
                   "--guidance", tmp_path / "u.npy")
    assert_one_error_line(done, "u.npy", "one value per input vertex (315)", "(100,)")
    assert not (tmp_path / "out.off").exists()
    (tmp_path / "bad.npy").write_text("not numpy")
    done = topstoc(DATA / "genus_positive" / "cgal_eight.off", tmp_path / "out.off", "--ratio", 0.1,
                   "--guidance", tmp_path / "bad.npy")
    assert_one_error_line(done, "bad.npy", "not a readable .npy file")
    u = np.zeros(315)
    u[17] = np.nan
    np.save(tmp_path / "nan.npy", u)
    done = topstoc(DATA / "genus_positive" / "cgal_eight.off", tmp_path / "out.off", "--ratio", 0.1,
                   "--guidance", tmp_path / "nan.npy")
    assert_one_error_line(done, "nan.npy", "guidance of vertex 17 is nan")


def test_stl_vertex_ids_follow_the_welded_order(tmp_path):
    source = DATA / "nonmanifold_degenerate" / "openscad_issue1580-back-to-back.stl"
    report = run_json(source, tmp_path / "out.stl", "--ratio", 1.0)
    assert report["input"]["vertices"] == 6 and report["input"]["triangles"] == 10


@pytest.mark.parametrize("args,fragments", [
    (["missing.obj", "out.obj", "--ratio", "0.5"], ["missing.obj"]),
    ([DATA / "nonmanifold_degenerate" / "openscad_unparseable.stl", "out.stl", "--ratio", "0.5"],
     ["openscad_unparseable.stl: line 4:", "is not a number"]),
    ([DATA / "nonmanifold_degenerate" / "openscad_empty.stl", "out.stl", "--ratio", "0.5"],
     ["openscad_empty.stl: the mesh has no triangles"]),
    ([DATA / "genus_positive" / "cgal_eight.off", "out.fbx", "--ratio", "0.5"], ["unknown mesh file extension"]),
    ([DATA / "genus_positive" / "cgal_eight.off", "out.off", "--ratio", "0"], ["ratio must lie in (0, 1]"]),
    ([DATA / "genus_positive" / "cgal_eight.off", "out.off", "--vertices", "100000"], ["vertex target 100000"]),
])
def test_bad_input_is_one_error_line(tmp_path, args, fragments):
    args = [tmp_path / a if isinstance(a, str) and a.startswith(("missing", "out")) else a for a in args]
    done = topstoc(*args)
    assert_one_error_line(done, *fragments)
    assert not list(tmp_path.glob("out*"))


def test_a_target_is_required(tmp_path):
    done = topstoc(DATA / "genus_positive" / "cgal_eight.off", tmp_path / "out.off")
    assert done.returncode == 2 and "one of the arguments" in done.stderr


def test_max_error(tmp_path):
    source = DATA / "genus_positive" / "cgal_elephant.off"
    done = topstoc(source, tmp_path / "out.off", "--max-error", "1%", "--json")
    if "max_error" not in inspect.signature(core_decimate).parameters:
        assert_one_error_line(done, "--max-error needs the error-bounded decimation")
        return
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["target"] == {"max_error": "1%"}
    original = read_mesh(source)
    assert read_mesh(tmp_path / "out.off").num_vertices == report["output"]["vertices"] < 2775
    diagonal = np.linalg.norm(original.vertices.max(0) - original.vertices.min(0))
    bound = report["error_bound"]
    assert bound["max_error"] == pytest.approx(0.01 * diagonal)
    assert 0 < bound["achieved_error"] <= bound["max_error"]
    bad = topstoc(source, tmp_path / "bad.off", "--max-error", "-1")
    assert_one_error_line(bad, "--max-error must be positive")


def _textured_obj(folder):
    """A UV-mapped torus OBJ with a .mtl naming one texture in a subfolder and one missing."""
    folder.mkdir()
    vertices, triangles = torus(24, 12)
    uvs = np.stack([vertices[triangles][..., 0], vertices[triangles][..., 1]], axis=-1)
    write_mesh(folder / "ring.obj", MeshData(vertices=vertices, triangles=triangles, corner_uvs=uvs,
                                             triangle_material=np.zeros(len(triangles), np.int32),
                                             material_names=["skin"], material_libraries=["ring.mtl"]))
    (folder / "textures").mkdir()
    (folder / "textures" / "skin.png").write_bytes(b"\x89PNG fake texture")
    (folder / "wood grain.png").write_bytes(b"\x89PNG grain")
    (folder / "ring.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd -s 1 1 1 textures/skin.png\n"
                                     "map_Ks -clamp on wood grain.png\nmap_Bump gone.png\n")
    return folder / "ring.obj"


def test_obj_materials_and_textures_follow_the_output(tmp_path):
    source = _textured_obj(tmp_path / "src")
    out = tmp_path / "out"
    out.mkdir()
    report = run_json(source, out / "low.obj", "--ratio", 0.3)
    assert report["output"]["dropped_attributes"] == []
    assert read_mesh(out / "low.obj").material_libraries == ["ring.mtl"]
    assert (out / "ring.mtl").read_bytes() == (source.parent / "ring.mtl").read_bytes()
    assert (out / "textures" / "skin.png").read_bytes() == b"\x89PNG fake texture"
    assert (out / "wood grain.png").read_bytes() == b"\x89PNG grain"  # a name with a space, after options
    assert sorted(p.name for p in out.iterdir()) == ["low.obj", "ring.mtl", "textures", "wood grain.png"]
    # the same folder as the input: nothing copied, the name kept
    run_json(source, source.parent / "low.obj", "--ratio", 0.3)
    assert read_mesh(source.parent / "low.obj").material_libraries == ["ring.mtl"]
    assert sorted(p.name for p in source.parent.iterdir()) == ["low.obj", "ring.mtl", "ring.obj", "textures",
                                                               "wood grain.png"]


def test_an_existing_different_mtl_is_never_overwritten(tmp_path):
    source = _textured_obj(tmp_path / "src")
    out = tmp_path / "out"
    out.mkdir()
    (out / "ring.mtl").write_text("newmtl other\n")
    done = topstoc(source, out / "low.obj", "--ratio", 0.3)
    assert done.returncode == 0
    assert done.stderr.splitlines() == [f"topstoc: warning: {out / 'ring.mtl'}: a different file already exists; "
                                        f"the output refers to {source.parent / 'ring.mtl'} instead"]
    assert (out / "ring.mtl").read_text() == "newmtl other\n"
    assert not (out / "textures").exists() and not (out / "wood grain.png").exists()
    assert read_mesh(out / "low.obj").material_libraries == ["../src/ring.mtl"]


def test_json_reports_the_attribute_weight_used_and_why_not(tmp_path):
    source = DATA / "uv_materials" / "spider" / "spider.obj"
    quality = run_json(source, tmp_path / "a.obj", "--ratio", 0.4)["attributes"]
    assert quality["weight"] == quality["requested_weight"] == 0.1 and "unused_because" not in quality
    assert quality["channels"] == ["uv.u", "uv.v"]
    fast = run_json_warned(source, tmp_path / "b.obj", "--ratio", 0.4, "--mode", "fast")["attributes"]
    assert fast["weight"] == 0.0 and fast["requested_weight"] == 0.1
    assert fast["unused_because"].startswith("fast mode")
    bare = run_json(DATA / "genus_positive" / "cgal_eight.off", tmp_path / "c.off", "--ratio", 0.4)["attributes"]
    assert bare["weight"] == 0.0 and bare["unused_because"] == "the input has no UVs or vertex colours"
    off = run_json(source, tmp_path / "d.obj", "--ratio", 0.4, "--attribute-weight", 0)["attributes"]
    assert off["weight"] == 0.0 and off["unused_because"] == "--attribute-weight 0"
