"""No command or batch writes over one of its inputs or into a folder it reads inputs from
(docs/design.md §6.1): refused with one line before any work, the input left byte for byte."""

import functools
import os

import pytest

import cli
import meshgen
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

batch = functools.partial(cli.run, "batch", timeout=300)


def _torus(path):
    path.parent.mkdir(parents=True, exist_ok=True)
    v, f = meshgen.torus(24, 12)
    write_mesh(path, MeshData(vertices=v, triangles=f))
    return path


@pytest.fixture
def ring(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    return _torus(tmp_path / "ring.obj")


def _aliases(ring):
    """Other names of the file ``ring``: relative spellings, a symlink and a hard link."""
    os.symlink("ring.obj", ring.parent / "link.obj")
    os.link(ring, ring.parent / "hard.obj")
    return ["ring.obj", "./ring.obj", str(ring), "sub/../ring.obj", "link.obj", "hard.obj"]


@pytest.mark.parametrize("command, extra, names", [("decimate", ("--ratio", 0.5), slice(None)),
                                                   ("fill-holes", (), slice(3, None, 2)),
                                                   ("remove-handle", ("--index", 0), slice(4, None)),
                                                   ("clean", (), slice(1, None, 2))])
def test_output_that_is_the_input_is_refused_under_every_name(ring, command, extra, names):
    before = ring.read_bytes()
    for output in _aliases(ring)[names]:
        done = cli.run(command, "ring.obj", output, *extra)
        cli.assert_one_error_line(command, done, f"{output}: the output is the input file", "--overwrite")
    done = cli.run(command, "link.obj", "ring.obj", *extra)  # the other way round: IN the link, OUT its target
    cli.assert_one_error_line(command, done, "ring.obj: the output is the input file link.obj")
    assert ring.read_bytes() == before
    assert sorted(p.name for p in ring.parent.iterdir()) == ["hard.obj", "link.obj", "ring.obj", "sub"]


def test_overwrite_replaces_the_input_atomically(ring):
    done = cli.run("decimate", "ring.obj", "./ring.obj", "--ratio", 0.5, "--overwrite")
    assert done.returncode == 0, done.stderr
    assert read_mesh(ring).num_vertices == 144  # 288 halved, once
    assert sorted(p.name for p in ring.parent.iterdir()) == ["ring.obj", "sub"]  # no temporary file left


def test_symlinked_output_is_written_through(ring, tmp_path):
    target = _torus(tmp_path / "elsewhere" / "target.obj")
    os.symlink("../elsewhere/target.obj", tmp_path / "sub" / "out.obj")
    done = cli.run("decimate", "ring.obj", "sub/out.obj", "--ratio", 0.25)
    assert done.returncode == 0, done.stderr
    assert os.readlink(tmp_path / "sub" / "out.obj") == "../elsewhere/target.obj"  # the link kept
    assert read_mesh(target).num_vertices == 72   # its target replaced
    assert sorted(p.name for p in target.parent.iterdir()) == ["target.obj"]


def test_errors_name_the_file_without_errno_text(ring, tmp_path):
    (tmp_path / "folder.obj").mkdir()
    for args, fragment in (((tmp_path / "folder.obj", "x.obj"), "folder.obj: is a directory"),
                           (("ring.obj", "folder.obj"), "folder.obj: cannot write the file (is a directory)"),
                           (("missing.obj", "x.obj"), "missing.obj: no such file or directory"),
                           (("ring.obj", "no/such/x.obj"), "x.obj: cannot write the file (no such file or directory)")):
        done = cli.run("decimate", *args, "--ratio", 0.5)
        cli.assert_one_error_line("decimate", done, fragment)
        assert "Errno" not in done.stderr


def test_measure_errors_file_is_not_an_input(ring):
    os.symlink("ring.obj", "errors.npz")
    done = cli.run("measure", "ring.obj", "errors.npz", "--errors", "errors.npz")
    cli.assert_one_error_line("measure", done, "errors.npz: the output is the input file ring.obj")


@pytest.mark.parametrize("output", ["D", "D/", "./D", "D/lods", "D/lods/deeper"])
def test_batch_into_its_input_folder_is_refused(tmp_path, monkeypatch, output):
    monkeypatch.chdir(tmp_path)
    ring = _torus(tmp_path / "D" / "ring.obj")
    before = ring.read_bytes()
    for _ in range(2):  # a rerun decimated the LODs again: 299 -> 150 -> 75 -> 38 vertices
        done = batch("--input", "D", "--output", output, "--ratio", 0.5, "--workers", 0)
        cli.assert_one_error_line("batch", done, f"--output {output}", "input folder D")
    assert ring.read_bytes() == before
    assert sorted(p.name for p in (tmp_path / "D").iterdir()) == ["ring.obj"]  # no manifest, report or LOD


def test_batch_reading_inside_its_output_folder_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _torus(tmp_path / "out" / "in" / "ring.obj")
    done = batch("--input", "out/in", "--output", "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "the input out/in lies inside --output out")
    done = batch("--input", "out/in/ring.obj", "--output", "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "the input out/in/ring.obj lies inside --output out")
    os.symlink("out", "alias")  # the same folder under another name
    done = batch("--input", "alias/in", "--output", "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "the input alias/in lies inside --output out")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["in"]


def test_batch_output_that_is_an_input_under_another_name_is_refused(tmp_path, monkeypatch):
    """A hard link of the input where the output goes, and an input that an earlier run wrote."""
    monkeypatch.chdir(tmp_path)
    ring = _torus(tmp_path / "in" / "ring.obj")
    (tmp_path / "out").mkdir()
    os.link(ring, tmp_path / "out" / "ring.obj")
    done = batch("--input", "in", "--output", "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "out/ring.obj: is the input in/ring.obj")
    os.remove(tmp_path / "out" / "ring.obj")
    assert batch("--input", "in", "--output", "out", "--ratio", 0.5, "--workers", 0).returncode == 0
    os.link(tmp_path / "out" / "ring.obj", tmp_path / "in" / "lod.obj")  # an output back among the inputs
    done = batch("--input", "in", "--output", "out", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "in/lod.obj: is out/ring.obj, an output of an earlier batch")
    assert read_mesh(tmp_path / "out" / "ring.obj").num_vertices == 144


def test_batch_report_that_is_an_input_and_output_that_is_a_file_are_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _torus(tmp_path / "in" / "ring.obj")
    done = batch("--input", "in", "--output", "out", "--json", "in/ring.obj", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "in/ring.obj: the output is the input file")
    (tmp_path / "afile").write_text("x")
    done = batch("--input", "in", "--output", "afile", "--ratio", 0.5, "--workers", 0)
    cli.assert_one_error_line("batch", done, "--output afile: is a file, not a folder")
    assert "Errno" not in done.stderr
