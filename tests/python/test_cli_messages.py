"""How the command line speaks: --version, one-line errors with exit 2 (usage) or 1 (failure) and
no errno text, one-line warnings never glued to a progress line, progress for long jobs, and an
explanation for every option in --help. Run as a subprocess like a user would (tests/cli.py)."""

import argparse
import io
import pathlib
import re
import time

import pytest

import cli
import meshgen
import topstoc
from topstoc.core.cli import build_parser, messages, progress
from topstoc.core.api.io import MeshData, write_mesh

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
EIGHT = DATA / "genus_positive" / "cgal_eight.off"
OLD_BLENDER_PLY = ("ply\nformat ascii 1.0\nCreated by Blender3D 247\nelement vertex 4\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                   "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")


def test_version_is_the_package_version_everywhere():
    done = cli.run("--version")
    assert done.returncode == 0 and done.stderr == ""
    assert done.stdout.strip() == f"topstoc {topstoc.__version__}"
    assert re.fullmatch(r"\d+\.\d+\.\d+", topstoc.__version__)
    # the files that repeat it agree with the one place it is set (bl_info)
    assert f'version = "{topstoc.__version__}"' in (ROOT / "pyproject.toml").read_text()
    assert f'version = "{topstoc.__version__}"' in (ROOT / "blender_manifest.toml").read_text()
    assert f"VERSION {topstoc.__version__} " in (ROOT / "CMakeLists.txt").read_text()


@pytest.mark.parametrize("args, command, fragment", [
    (["decimate", EIGHT, "out.off"], "topstoc decimate", "one of the arguments --ratio"),
    (["decimate", EIGHT, "out.off", "--ratio", "half"], "topstoc decimate", "invalid float value: 'half'"),
    (["decimate", EIGHT, "out.off", "--ratio", "0.5", "--bogus"], "topstoc", "unrecognized arguments: --bogus"),
    (["batch", "--output", "out", "--ratio", "0.5"], "topstoc batch", "--input"),
    (["measure", EIGHT], "topstoc measure", "required: B"),
    (["frobnicate"], "topstoc", "invalid choice: 'frobnicate'"),
])
def test_usage_errors_are_one_line_and_exit_2(tmp_path, args, command, fragment):
    done = cli.run(*[tmp_path / a if a in ("out.off", "out") else a for a in args])
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr  # no usage dump
    assert lines[0].startswith(f"{command}: error: ") and fragment in lines[0], lines[0]
    assert lines[0].endswith(f"(see '{command} --help')")
    assert done.stdout == ""


def test_failures_say_os_errors_in_words_naming_the_file(tmp_path):
    folder = tmp_path / "folder.off"
    folder.mkdir()
    cases = [
        ((folder, tmp_path / "out.off"), f"{folder}: is a directory"),
        ((EIGHT, folder), f"{folder}: cannot write the file (is a directory)"),
        ((tmp_path / "missing.off", tmp_path / "out.off"), f"{tmp_path / 'missing.off'}: no such file or directory"),
        ((EIGHT, tmp_path / "no" / "out.off"), "no such file or directory"),
    ]
    for (source, target), expected in cases:
        done = cli.run("decimate", source, target, "--ratio", 0.5)
        cli.assert_one_error_line("decimate", done, expected)
        assert "Errno" not in done.stderr and "Traceback" not in done.stderr


def test_os_error_text_without_errno():
    assert messages.error_text(IsADirectoryError(21, "Is a directory", "/x")) == "/x: is a directory"
    assert messages.error_text(FileExistsError(17, "File exists", "a", None, "b")) == "a -> b: already exists"
    wrapped = OSError(28, "out.ply: cannot write the file (No space left on device)")
    assert messages.error_text(wrapped) == "out.ply: cannot write the file (no space left on device)"
    assert messages.error_text(OSError(1234, "Odd Thing")) == "Odd Thing"


def test_a_warning_is_one_line_without_python_source(tmp_path):
    (tmp_path / "old.ply").write_text(OLD_BLENDER_PLY)
    done = cli.run("topology", tmp_path / "old.ply")
    assert done.returncode == 0
    assert done.stderr.splitlines() == [
        f"topstoc: warning: {tmp_path / 'old.ply'}: line 3: skipped unknown PLY header line 'Created by Blender3D 247'"]
    quiet = cli.run("topology", tmp_path / "old.ply", "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == ""
    assert quiet.stdout.splitlines()[:-1] == done.stdout.splitlines()[:-1]  # the last line is the time


def test_progress_on_request_for_a_long_job_and_never_with_json(tmp_path):
    args = ("decimate", DATA / "genus_positive" / "cgal_elephant.off", tmp_path / "out.off", "--max-error", "0.3%")
    started = time.monotonic()
    done = cli.run(*args, "--progress")
    took = time.monotonic() - started
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    if took > 2.5:  # the search runs over a second on any machine this suite runs on
        assert lines and all(re.fullmatch(r"topstoc decimate: .+ \.\.\. \d+ s", line) for line in lines), lines
        assert any("searching the vertex count for --max-error 0.3%" in line for line in lines)
    # without a terminal and without --progress: nothing; --json and --quiet: nothing either
    assert cli.run(*args).stderr == ""
    assert cli.run(*args, "--progress", "--json").stderr == ""
    assert cli.run(*args, "--progress", "--quiet").stderr == ""


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_warning_never_shares_the_progress_line(monkeypatch):
    terminal = _Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    monkeypatch.setattr(progress, "DELAY_SECONDS", 0.0)
    monkeypatch.setattr(progress, "TICK_SECONDS", 0.01)
    progress.set_quiet(False)
    progress.start("topstoc decimate", stream=terminal)
    try:
        progress.stage("decimating")
        deadline = time.monotonic() + 5
        while "decimating" not in terminal.getvalue() and time.monotonic() < deadline:
            time.sleep(0.01)
        messages.print_warning("a.obj: something skipped")
        time.sleep(0.05)
    finally:
        progress.stop()
    text = terminal.getvalue()
    assert "topstoc decimate: decimating ... 0 s" in text
    # the warning starts right after the progress line was erased, and ends its own line
    before, warning, after = text.partition("topstoc: warning: a.obj: something skipped\n")
    assert warning and before.endswith("\r\x1b[K")
    assert text.endswith("\r\x1b[K")  # stopping clears the line: the prompt comes back clean


def _options(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from ((f"{name} {o}", h) for o, h in _options(sub))
        elif not isinstance(action, argparse._HelpAction):
            yield "/".join(action.option_strings) or action.dest, action.help


def test_every_option_has_help():
    missing = [name for name, text in _options(build_parser()) if not text or not text.strip()]
    assert missing == []
    for command in ("decimate", "batch", "measure", "topology", "loops", "fill-holes", "remove-handle"):
        text = cli.run(command, "--help").stdout
        assert "%%" not in text and text.startswith(f"usage: topstoc {command} "), command
    shown = cli.run("batch", "--help").stdout
    for option in ("--output DIR", "--seed S", "--adaptivity A", "--keep-compression", "--quiet"):
        assert option in shown
    assert "folder for the outputs" in shown and "random seed" in shown and "curvature" in shown


def test_symmetry_on_an_asymmetric_mesh_warns(tmp_path):
    v, f = meshgen.torus(24, 12)
    v[:, 0] += 0.3  # off the x = 0 plane: no vertex has a mirror partner
    write_mesh(tmp_path / "ring.ply", MeshData(vertices=v, triangles=f))
    done = cli.run("decimate", tmp_path / "ring.ply", tmp_path / "out.ply", "--ratio", 0.3, "--symmetry", "x")
    assert done.returncode == 0
    assert done.stderr.splitlines() == [
        "topstoc: warning: --symmetry x: the mesh is not symmetric across the plane x = 0: 288 of 288 vertices "
        "(100 %) have no mirror partner; the result is symmetric only where the input is"]
    # across y the torus is symmetric: no warning
    ok = cli.run("decimate", tmp_path / "ring.ply", tmp_path / "out.ply", "--ratio", 0.3, "--symmetry", "y")
    assert ok.returncode == 0 and ok.stderr == ""


def _slowed(module: str, name: str, seconds: float) -> str:
    """Python that runs the command line with ``module.name`` made ``seconds`` slower, so that a
    progress line drawn after a second shows however fast the machine is."""
    return (f"import sys, time; import {module} as m; real = m.{name}; "
            f"m.{name} = lambda *a, **k: (time.sleep({seconds}), real(*a, **k))[1]; "
            "from topstoc.core.cli import main; sys.exit(main(sys.argv[1:]))")


def _on_a_terminal(*args, code: str = None) -> str:
    """Everything ``topstoc ARGS`` writes to a terminal (stdout and stderr on one pty); ``code``:
    Python run instead of ``-m topstoc`` (it reads ARGS from sys.argv[1:])."""
    import os
    import subprocess
    import sys

    from conftest import BUILD
    from terminal import open_terminal, read_all

    primary, secondary = open_terminal()
    command = [sys.executable, "-c", code] if code else [sys.executable, "-m", "topstoc"]
    process = subprocess.Popen([*command, *map(str, args)], stdout=secondary,
                               stderr=secondary, env=dict(os.environ, PYTHONPATH=str(BUILD / "python")))
    os.close(secondary)
    text = read_all(primary, process, timeout=120)
    os.close(primary)
    assert process.wait(timeout=120) == 0
    return text


def test_on_a_terminal_progress_is_erased_before_the_report(tmp_path):
    text = _on_a_terminal("decimate", DATA / "genus_positive" / "cgal_elephant.off", tmp_path / "out.off",
                          "--max-error", "0.3%", code=_slowed("topstoc.core.api.mesh_file_job", "prepare_file", 1.5))
    pieces = text.split("\r\x1b[K")
    drawn = [p for p in pieces if p.startswith("topstoc decimate: ")]
    assert drawn, text  # the search outlasts the one-second delay
    # each drawn progress line is erased before anything else is written: nothing glued to it
    assert all(re.fullmatch(r"topstoc decimate: .+ \.\.\. \d+ s", p) for p in drawn), drawn
    assert pieces[-1].startswith(f"{DATA / 'genus_positive' / 'cgal_elephant.off'}: 2775 vertices")


def test_on_a_terminal_a_long_batch_asset_shows_its_clock(tmp_path):
    text = _on_a_terminal("batch", "--input", DATA / "genus_positive" / "cgal_elephant.off", "--output", tmp_path,
                          "--max-error", "0.3%", "--workers", 0,
                          code=_slowed("topstoc.core.batch.mesh_asset", "decimate_mesh_file", 2.5))
    # a bar (tqdm installed) or the ticker line: either way the clock runs while the asset works
    clocks = re.findall(r"topstoc batch: (?:0 of 1 assets done \.\.\. (\d+) s|.*?\| 0/1 \[(\d\d:\d\d)<)", text)
    assert len(set(clocks)) >= 2, text  # redrawn with a later time while the one asset works
    assert text.rstrip().splitlines()[-1].startswith("topstoc batch: 1 done, 0 skipped, 0 failed")
