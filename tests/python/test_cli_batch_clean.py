"""``topstoc batch --clean``: each asset cleaned as ``topstoc clean`` does, then decimated; the
report says what was removed and what was left. Topology checked with GUDHI, not the engine."""

import argparse
import functools
import json

import cleanup_meshes
import cli
from topology_checks import gudhi_betti
from topstoc.core.api.io import MeshData, read_mesh, write_mesh
from topstoc.core.batch import settings as batch_settings

batch = functools.partial(cli.run, "batch", timeout=300)


def _write(path, vertices, triangles):
    path.parent.mkdir(exist_ok=True)
    write_mesh(path, MeshData(vertices=vertices, triangles=triangles))
    return path.read_bytes()


def test_batch_clean_removes_small_handles_and_holes_before_decimating(tmp_path):
    folder, out = tmp_path / "in", tmp_path / "out"
    # 3 unit arches (loops about 4 long) and one of size 3 (loops about 12) on a block: genus 4.
    arches = _write(folder / "arches.obj", *cleanup_meshes.block_with_arches(3, 1, jitter=0.05, seed=3))
    # A plate with 3 small square holes (border 4) and one large (border 16).
    plate = _write(folder / "plate.off", *cleanup_meshes.perforated_plate(3, 1, side=24, seed=4))
    for name in ("arches.obj", "plate.off"):
        source = read_mesh(folder / name)
        assert gudhi_betti(source.num_vertices, source.triangles)[1] == {"arches.obj": 8, "plate.off": 4}[name]

    done = batch("--input", folder, "--output", out, "--ratio", 0.6, "--clean", "--max-handle", 6,
                 "--max-hole", 6, "--workers", 0)
    assert done.returncode == 0, done.stderr
    assert "cleaned: 3 handles removed, 0 holes filled" in done.stdout
    assert "cleaned: 0 handles removed, 3 holes filled" in done.stdout
    assert (folder / "arches.obj").read_bytes() == arches and (folder / "plate.off").read_bytes() == plate

    report = json.loads((out / "topstoc-report.json").read_text())
    assert report["settings"]["clean"] == {"max_handle": "6", "max_hole": "6", "keep_largest": None, "fair": True}
    entries = {entry["input"].rsplit("/", 1)[-1]: entry for entry in report["results"]}
    cleaned = entries["arches.obj"]["clean"]
    assert (cleaned["genus_before"], cleaned["genus_after"], cleaned["handles_removed"]) == (4, 1, 3)
    assert all(item["edges"] == 4 for item in cleaned["removed"])
    # The large arch's handle and tunnel loops stay, each with its reason.
    assert len(cleaned["left"]) == 2 and all("not below the size 6" in item["reason"] for item in cleaned["left"])
    holes = entries["plate.off"]["clean"]
    assert holes["holes_filled"] == 3 and {item["kind"] for item in holes["removed"]} == {"hole"}
    left_holes = [item for item in holes["left"] if item["kind"] == "hole"]
    assert sorted(round(item["loop_length"]) for item in left_holes) == [16, 96]  # the large hole, the rim
    assert all("not below the size" in item["reason"] for item in left_holes)

    # Outputs: one handle left (betti1 = 2 on a closed surface); a plate with one hole left (betti1 = 1).
    for name, betti in (("arches.obj", (1, 2, 1)), ("plate.off", (1, 1, 0))):
        output = read_mesh(out / name)
        assert tuple(gudhi_betti(output.num_vertices, output.triangles)) == betti, name
        assert output.num_vertices < 0.7 * read_mesh(folder / name).num_vertices  # decimated too
    # The counts in are the file's, before its clean-up; the output is decimated from the cleaned mesh.
    assert entries["arches.obj"]["vertices_in"] == read_mesh(folder / "arches.obj").num_vertices


def test_clean_options_reach_the_blender_batch_and_need_clean():
    parser = argparse.ArgumentParser()
    batch_settings.add_arguments(parser)
    settings = batch_settings.from_args(parser.parse_args(
        ["--ratio", "0.5", "--clean", "--max-handle", "2%", "--keep-largest", "3", "--flat"]))
    assert settings["clean"] == {"max_handle": "2%", "max_hole": None, "keep_largest": 3, "fair": False}
    argv = batch_settings.to_argv(settings)
    assert batch_settings.from_args(parser.parse_args(argv)) == settings  # the Blender subprocess's copy
    plain = batch_settings.from_args(parser.parse_args(["--ratio", "0.5"]))
    assert "clean" not in plain and "--clean" not in batch_settings.to_argv(plain)
    assert batch_settings.digest(plain) != batch_settings.digest(settings)  # a rerun with --clean redoes the asset


def test_clean_options_without_clean_are_one_error_line(tmp_path):
    source = tmp_path / "in" / "arches.obj"
    _write(source, *cleanup_meshes.block_with_arches(1, 0))
    done = batch("--input", source, "--output", tmp_path / "out", "--ratio", 0.5, "--max-hole", "1%",
                 "--workers", 0)
    cli.assert_one_error_line("batch", done, "--max-hole is an option of --clean")
    done = batch("--input", source, "--output", tmp_path / "out", "--ratio", 0.5, "--clean", "--keep-largest", -2,
                 "--workers", 0)
    cli.assert_one_error_line("batch", done, "--keep-largest must be 0 or more")
