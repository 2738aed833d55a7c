"""``topstoc batch`` serially (--workers 0, no Dask needed): LOD chains of mesh files, format
conversion, chunks, and clear errors. The Dask runner is tested in tests/pipeline."""

import functools
import json

import cli
import meshgen
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

batch = functools.partial(cli.run, "batch", timeout=300)


def _torus(folder, name="ring.obj"):
    folder.mkdir(exist_ok=True)
    v, f = meshgen.torus(24, 12)
    write_mesh(folder / name, MeshData(vertices=v, triangles=f))
    return folder / name


def test_lod_chain_of_a_mesh_file_converted_to_ply(tmp_path):
    source = _torus(tmp_path / "in")
    out = tmp_path / "out"
    done = batch("--input", source, "--output", out, "--ratio", 1, 0.5, 0.2, "--format", "ply", "--workers", 0)
    assert done.returncode == 0, done.stderr
    [entry] = json.loads((out / "topstoc-report.json").read_text())["results"]
    names = [lod["output"].rsplit("/", 1)[-1] for lod in entry["lods"]]
    assert names == ["ring_LOD0.ply", "ring_LOD1.ply", "ring_LOD2.ply"]
    counts = [read_mesh(out / name).num_vertices for name in names]
    assert counts == [lod["vertices"] for lod in entry["lods"]] and counts[0] == 288 > counts[1] > counts[2]
    errors = [lod["hausdorff"] for lod in entry["lods"]]
    assert errors[0] < 1e-12 and 0 < errors[1] < errors[2]


def test_chunks_split_the_inputs_and_empty_chunks_are_fine(tmp_path):
    for i in range(3):
        _torus(tmp_path / "in", f"ring{i}.off")
    out = tmp_path / "out"
    seen = []
    for index in (1, 2, 3, 4):
        done = batch("--input", tmp_path / "in", "--output", out, "--ratio", 0.5, "--chunk", f"{index}/4",
                     "--workers", 0)
        assert done.returncode == 0, done.stderr
        if index < 4:
            report = json.loads((out / f"topstoc-report-chunk{index}of4.json").read_text())
            seen += [r["input"].rsplit("/", 1)[-1] for r in report["results"]]
        else:
            assert "has no inputs" in done.stdout
    assert sorted(seen) == ["ring0.off", "ring1.off", "ring2.off"]
    # The chunks' manifests together make a full rerun skip everything.
    done = batch("--input", tmp_path / "in", "--output", out, "--ratio", 0.5, "--workers", 0)
    assert len(json.loads((out / "topstoc-report.json").read_text())["skipped"]) == 3


def test_clear_errors(tmp_path):
    a = _torus(tmp_path / "a", "ring.obj")
    b = _torus(tmp_path / "b", "ring.obj")
    done = batch("--input", a, b, "--output", tmp_path / "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "would both write")
    done = batch("--input", a, "--output", tmp_path / "out", "--ratio", 0.5, "--chunk", "5/4", "--workers", 0)
    cli.assert_one_error_line("batch", done, "--chunk")
    done = batch("--input", a, "--output", tmp_path / "out", "--ratio", 1.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "--ratio values must lie in (0, 1]")
    done = batch("--input", tmp_path / "nothing", "--output", tmp_path / "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "nothing: no such file or folder")
    (tmp_path / "empty").mkdir()
    done = batch("--input", tmp_path / "empty", "--output", tmp_path / "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "no input assets found")


def test_orphaned_scratch_of_dead_processes_is_removed(tmp_path):
    """A worker killed during a Blender task leaves its scratch folder; the next batch removes
    the folders whose owner is gone, and only those."""
    import os
    import subprocess
    import sys

    from topstoc.core.batch.run import remove_orphaned_scratch

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead_pid = int(gone.stdout)
    names = {f"topstoc-batch-{dead_pid}-abc": False, f"topstoc-batch-{os.getpid()}-def": True,
             "topstoc-batch-notapid-x": True, "unrelated-1": True}
    for name in names:
        (tmp_path / name).mkdir()
        (tmp_path / name / "report.json").write_text("{}")
    assert remove_orphaned_scratch(str(tmp_path)) == 1
    assert {p.name for p in tmp_path.iterdir()} == {name for name, kept in names.items() if kept}


def test_progress_summary_of_a_scene_with_lods():
    """A Blender asset's LOD chain: the progress line sums each LOD over the scene's objects."""
    from topstoc.core.cli.batch import _summary

    entry = {"vertices_in": 300, "vertices_out": 150, "triangles_out": 290,
             "objects": [{"lods": [{"vertices": 100}, {"vertices": 40}, {"vertices": 10}]},
                         {"lods": [{"vertices": 50}, {"vertices": 20}, {"vertices": 5}]}]}
    assert _summary(entry) == "300 -> 150 / 60 / 15 vertices (3 LODs)"
    single = {"vertices_in": 300, "vertices_out": 150, "triangles_out": 290, "objects": [{"lods": [{"vertices": 150}]}]}
    assert _summary(single) == "300 -> 150 vertices, 290 triangles"


def test_a_resumed_batch_keeps_the_finished_assets_figures(tmp_path):
    for name in ("a.obj", "b.off"):
        _torus(tmp_path / "in", name)
    out = tmp_path / "out"
    assert batch("--input", tmp_path / "in", "--output", out, "--ratio", 0.5, 0.25, "--workers", 0).returncode == 0
    first = json.loads((out / "topstoc-report.json").read_text())["results"]
    _torus(tmp_path / "in", "c.ply")
    done = batch("--input", tmp_path / "in", "--output", out, "--ratio", 0.5, 0.25, "--workers", 0)
    assert done.returncode == 0, done.stderr
    report = json.loads((out / "topstoc-report.json").read_text())
    assert [r["input"].rsplit("/", 1)[-1] for r in report["results"]] == ["a.obj", "b.off", "c.ply"]
    assert [r.get("resumed") for r in report["results"]] == [True, True, None]
    for earlier, kept in zip(first, report["results"]):
        assert [lod["vertices"] for lod in kept["lods"]] == [lod["vertices"] for lod in earlier["lods"]] == [144, 72]
        assert kept["lods"][1]["hausdorff"] == earlier["lods"][1]["hausdorff"] > 0
    assert len(report["skipped"]) == 2 and "1 done, 2 skipped" in done.stdout


def test_a_file_name_that_is_not_utf8_fails_that_asset_only(tmp_path):
    import os

    source = _torus(tmp_path / "in", "ring.obj")
    bad = os.path.join(os.fsencode(tmp_path / "in"), b"caf\xe9.obj")
    with open(bad, "wb") as stream:
        stream.write(source.read_bytes())
    out = tmp_path / "out"
    done = batch("--input", tmp_path / "in", "--output", out, "--ratio", 0.5, "--workers", 0)
    assert done.returncode == 1
    message = f"{tmp_path}/in/caf\\xe9.obj: the file name is not valid UTF-8; rename the file"
    assert done.stderr.strip().splitlines() == [f"topstoc batch [1/2] {tmp_path}/in/caf\\xe9.obj: FAILED: {message}"]
    report = json.loads((out / "topstoc-report.json").read_text())
    assert report["failures"] == [{"input": f"{tmp_path}/in/caf\\xe9.obj", "message": message}]
    assert [r["vertices_out"] for r in report["results"]] == [144]
    assert sorted(os.listdir(out)) == ["ring.obj", "topstoc-manifest.jsonl", "topstoc-report.json"]
def test_lod_chains_are_finest_first_whatever_the_order_given(tmp_path):
    source = _torus(tmp_path / "in")
    for order in ((0.1, 0.5), (0.5, 0.1)):
        out = tmp_path / f"out{order[0]}"
        done = batch("--input", source, "--output", out, "--ratio", *order, "--workers", 0)
        assert done.returncode == 0, done.stderr
        [entry] = json.loads((out / "topstoc-report.json").read_text())["results"]
        assert [lod["target"] for lod in entry["lods"]] == [{"ratio": 0.5}, {"ratio": 0.1}]
        counts = [read_mesh(out / f"ring_LOD{i}.obj").num_vertices for i in (0, 1)]
        assert counts[0] > counts[1]  # LOD0 the most detailed
    # error and distance targets: smaller is finer
    out = tmp_path / "by_error"
    done = batch("--input", source, "--output", out, "--max-error", "4%", "1%", "--workers", 0)
    assert done.returncode == 0, done.stderr
    [entry] = json.loads((out / "topstoc-report.json").read_text())["results"]
    assert [lod["target"]["max_error"] for lod in entry["lods"]] == [0.01, 0.04]
    assert entry["lods"][0]["vertices"] > entry["lods"][1]["vertices"]
    mixed = batch("--input", source, "--output", tmp_path / "mixed", "--max-error", "1%", "0.1", "--workers", 0)
    cli.assert_one_error_line("batch", mixed, "must all be in % or all absolute")


def test_compressed_inputs_give_uncompressed_outputs_unless_asked(tmp_path):
    v, f = meshgen.torus(24, 12)
    (tmp_path / "in").mkdir()
    write_mesh(tmp_path / "in" / "ring.ply.gz", MeshData(vertices=v, triangles=f))
    done = batch("--input", tmp_path / "in", "--output", tmp_path / "plain", "--ratio", 0.5, "--workers", 0)
    assert done.returncode == 0, done.stderr
    assert [p.name for p in (tmp_path / "plain").glob("ring*")] == ["ring.ply"]
    assert (tmp_path / "plain" / "ring.ply").read_bytes().startswith(b"ply\n")
    kept = batch("--input", tmp_path / "in", "--output", tmp_path / "kept", "--ratio", 0.5, "--workers", 0,
                 "--keep-compression")
    assert kept.returncode == 0, kept.stderr
    assert (tmp_path / "kept" / "ring.ply.gz").read_bytes()[:2] == b"\x1f\x8b"  # gzip magic
    assert read_mesh(tmp_path / "kept" / "ring.ply.gz").num_vertices == read_mesh(tmp_path / "plain" / "ring.ply").num_vertices


def test_warnings_come_back_with_the_asset_one_line_each(tmp_path):
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "old.ply").write_text(
        "ply\nformat ascii 1.0\nCreated by Blender3D 247\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
    done = batch("--input", tmp_path / "in", "--output", tmp_path / "out", "--ratio", 1, "--workers", 0)
    assert done.returncode == 0, done.stderr
    expected = f"topstoc: warning: {tmp_path / 'in' / 'old.ply'}: line 3: skipped unknown PLY header line 'Created by Blender3D 247'"
    assert done.stderr.splitlines() == [expected]
    [entry] = json.loads((tmp_path / "out" / "topstoc-report.json").read_text())["results"]
    assert entry["warnings"] == [expected[len("topstoc: warning: "):]]
    # the task itself carries them back (a Dask worker's outcome travels the same way)
    from topstoc.core.batch.run import run_asset
    from topstoc.core.batch.settings import from_args
    from topstoc.core.cli import build_parser

    settings = from_args(build_parser().parse_args(["batch", "--input", "x", "--output", "y", "--ratio", "1"]))
    (tmp_path / "again").mkdir()
    outcome = run_asset(str(tmp_path / "in" / "old.ply"), str(tmp_path / "again"), settings)
    assert outcome["status"] == "done" and outcome["warnings"] == entry["warnings"]
    quiet = batch("--input", tmp_path / "in", "--output", tmp_path / "q", "--ratio", 1, "--workers", 0, "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_obj_lods_get_the_mtl_beside_them_and_report_dropped_normals(tmp_path):
    import pathlib

    spider = pathlib.Path(__file__).resolve().parents[1] / "data" / "uv_materials" / "spider" / "spider.obj"
    out = tmp_path / "out"
    done = batch("--input", spider, "--output", out, "--ratio", 0.5, 0.2, "--workers", 0)
    assert done.returncode == 0, done.stderr
    [entry] = json.loads((out / "topstoc-report.json").read_text())["results"]
    for lod in entry["lods"]:
        assert read_mesh(lod["output"]).material_libraries == ["spider.mtl"]
        assert lod["dropped_attributes"] == ["normals"]  # the spider's vn lines are not written
    assert (out / "spider.mtl").read_bytes() == (spider.parent / "spider.mtl").read_bytes()


def test_bake_normals_is_checked_and_mapless_outputs_refuse_it(tmp_path):
    """``--bake-normals SIZE`` reaches the Blender batch through the settings (to_argv); a bad size
    is one error line; a mesh file (baked through Blender) fails with a reason, before any Blender
    runs, when its output has no material for the map or Blender cannot read it."""
    from topstoc.core.batch import settings as batch_settings

    a = _torus(tmp_path / "a", "ring.obj")
    done = batch("--input", a, "--output", tmp_path / "out", "--ratio", 0.5, "--bake-normals", 8, "--workers", 0)
    cli.assert_one_error_line("batch", done, "normal map size must be a whole number of pixels from 16")
    done = batch("--input", a, "--output", tmp_path / "out", "--ratio", 0.5, "--bake-normals", 64, "--workers", 0,
                 "--format", "stl", "--blender", tmp_path / "no-blender")
    assert done.returncode == 1 and "ring.obj: a .stl output has no material to reference the baked maps: pass " \
        "--format obj" in done.stdout + done.stderr
    assert not (tmp_path / "out" / "ring.stl").exists()
    packed = tmp_path / "b" / "ring.obj.gz"
    packed.parent.mkdir()
    write_mesh(packed, read_mesh(a))
    done = batch("--input", packed, "--output", tmp_path / "out2", "--ratio", 0.5, "--bake-normals", 64,
                 "--workers", 0, "--blender", tmp_path / "no-blender")
    assert done.returncode == 1 and "ring.obj.gz: --bake-normals imports OBJ files with Blender, which reads no " \
        ".gz: decompress the file" in done.stdout + done.stderr
    parser = __import__("argparse").ArgumentParser()
    batch_settings.add_arguments(parser)
    settings = batch_settings.from_args(parser.parse_args(["--ratio", "0.5", "--bake-normals", "512"]))
    assert settings["bake_normals"] == 512 and batch_settings.to_argv(settings)[-2:] == ["--bake-normals", "512"]
    plain = batch_settings.from_args(parser.parse_args(["--ratio", "0.5"]))
    assert "bake_normals" not in plain and "--bake-normals" not in batch_settings.to_argv(plain)


def test_bake_colour_needs_bake_normals(tmp_path):
    """``--bake-colour`` alone is one error line naming --bake-normals; with it, the settings carry it
    to the Blender batch (to_argv) and leave the settings of a run without it as they were."""
    from topstoc.core.batch import settings as batch_settings

    a = _torus(tmp_path / "a", "ring.obj")
    done = batch("--input", a, "--output", tmp_path / "out", "--ratio", 0.5, "--bake-colour", "--workers", 0)
    cli.assert_one_error_line("batch", done, "--bake-colour needs --bake-normals SIZE")
    assert not (tmp_path / "out").exists()
    parser = __import__("argparse").ArgumentParser()
    batch_settings.add_arguments(parser)
    settings = batch_settings.from_args(parser.parse_args(["--ratio", "0.5", "--bake-normals", "64", "--bake-colour"]))
    assert settings["bake_colour"] is True
    assert batch_settings.to_argv(settings)[-3:] == ["--bake-normals", "64", "--bake-colour"]
    again = batch_settings.from_args(parser.parse_args(batch_settings.to_argv(settings)))
    assert again == settings
    normals_only = batch_settings.from_args(parser.parse_args(["--ratio", "0.5", "--bake-normals", "64"]))
    assert "bake_colour" not in normals_only and "--bake-colour" not in batch_settings.to_argv(normals_only)


def test_the_error_report_is_a_bracket_and_exact_on_request(tmp_path):
    """Default: a bounded estimate (estimate <= upper, both against an independent exact
    measurement, converged within 25 %); --exact-error: the exact bracketed max, within 0.1 %."""
    from topstoc.core.api.hausdorff import hausdorff
    source = _torus(tmp_path / "in")
    lods = {}
    for flag in ((), ("--exact-error",)):
        out = tmp_path / ("exact" if flag else "estimate")
        done = batch("--input", source, "--output", out, "--ratio", 0.3, "--workers", 0, *flag)
        assert done.returncode == 0, done.stderr
        [entry] = json.loads((out / "topstoc-report.json").read_text())["results"]
        [lods[bool(flag)]] = entry["lods"]
        truth = hausdorff(read_mesh(source), read_mesh(entry["output"]), samples=300_000, percentile=0).symmetric
        lod = lods[bool(flag)]
        assert lod["hausdorff"] <= truth.max_upper and lod["hausdorff_upper"] >= truth.max
        assert lod["hausdorff_kind"] == ("exact" if flag else "estimate")
        # the report names its bound: upper within (1 + hausdorff_gap) times the distance attained
        assert lod["hausdorff_gap"] == (0.001 if flag else 0.25)
        assert lod["hausdorff_upper"] <= lod["hausdorff"] * (1 + lod["hausdorff_gap"]) + 1e-12
    assert lods[False]["hausdorff_converged"]
