"""The README as its readers meet it (issue 38): its examples run as written, its headline figures
are the ones docs/benchmarks.md holds, and it stays short (no hashes, dates or giant cells).

Fenced blocks whose info string is ``console example`` or ``python example`` are the examples:
console lines ``$ topstoc ...`` run as ``python -m topstoc ...`` in a folder holding the bundled
elephant as ``elephant.off`` and ``assets/elephant.off``; the Python block runs from the checkout.
"""

import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys

import numpy as np
import pytest

from conftest import BUILD, DATA, ROOT
from topstoc.core.api.io import read_mesh

README = (ROOT / "README.md").read_text()
ELEPHANT = DATA / "genus_positive" / "cgal_elephant.off"
FENCE = re.compile(r"^```([^\n]*)\n(.*?)^```$", re.S | re.M)


def blocks(kind: str) -> list[str]:
    """The README's fenced blocks marked ``<kind> example``."""
    return [body for info, body in FENCE.findall(README) if info.split() == [kind, "example"]]


def console_commands() -> list[list[str]]:
    commands = []
    for body in blocks("console"):
        for line in body.splitlines():
            assert line.startswith("$ topstoc "), f"an example line must be a topstoc command: {line!r}"
            commands.append(shlex.split(line[2:], comments=True))
    return commands


def test_readme_is_short_and_free_of_run_logs():
    lines = README.splitlines()
    assert len(lines) <= 180
    assert not re.search(r"\b20\d\d-\d\d-\d\d\b", README), "a date in the README"
    hashes = [word for word in re.findall(r"\b[0-9a-f]{7,40}\b", README) if re.search(r"[a-f]", word)
              and re.search(r"\d", word)]
    assert not hashes, f"commit hashes in the README: {hashes}"
    cells = [cell.strip() for line in lines if line.startswith("|") for cell in line.strip("|").split(" | ")]
    assert cells and max(map(len, cells)) <= 200


def test_quick_start_is_exactly_the_two_scripts():
    section = README.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    [body] = [body for _, body in FENCE.findall(section)]
    assert body.split() == ["./scripts/demo.sh", "./scripts/test.sh"]
    for script in body.split():
        assert os.access(ROOT / script, os.X_OK), script
    assert os.access(ROOT / "scripts" / "release.sh", os.X_OK)  # Install names it


def test_links_to_files_in_the_checkout_exist():
    targets = re.findall(r"\]\(([^)#:]+)\)", README)
    assert "docs/demo-dragon.png" in targets and "docs/benchmarks.md" in targets
    missing = [target for target in targets if not (ROOT / target).exists()]
    assert not missing


def test_headline_figures_are_those_of_docs_benchmarks():
    """Every TopStoc figure and peer ratio of the Measured table appears in docs/benchmarks.md."""
    section = README.split("## Measured", 1)[1].split("\n## ", 1)[0]
    rows = [line.strip("|").split(" | ") for line in section.splitlines() if line.startswith("| ")][1:]
    assert 5 <= len(rows) <= 7
    benchmarks = (ROOT / "docs" / "benchmarks.md").read_text()
    for _, figure, versus in rows:
        quantity = re.search(r"\d[\d.,/–]*", figure).group(0)
        ratio = re.search(r"\d[\d.–]*×", versus).group(0)
        assert quantity in benchmarks, (figure, quantity)
        assert ratio in benchmarks, (versus, ratio)


def test_console_examples_run_as_written(tmp_path):
    commands = console_commands()
    assert [c[:2] for c in commands[:2]] == [["topstoc", "decimate"]] * 2 and len(commands) >= 6
    shutil.copy(ELEPHANT, tmp_path / "elephant.off")
    (tmp_path / "assets").mkdir()
    shutil.copy(ELEPHANT, tmp_path / "assets" / "elephant.off")
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    for command in commands:
        done = subprocess.run([sys.executable, "-m", "topstoc", *command[1:]], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, (command, done.stderr)
    source = read_mesh(ELEPHANT).num_vertices
    tenth = read_mesh(tmp_path / "elephant-10.obj").num_vertices
    assert abs(tenth - 0.1 * source) <= 0.01 * 0.1 * source + 1  # the target, within the 1 % budget
    assert read_mesh(tmp_path / "elephant-fast.ply").num_vertices < tenth
    lods = sorted((tmp_path / "lods").glob("elephant_LOD*.off"))
    assert [read_mesh(path).num_vertices for path in lods] == [round(0.5 * source), round(0.1 * source)]


def test_python_example_runs_as_written(monkeypatch, capsys):
    [code] = blocks("python")
    monkeypatch.chdir(ROOT)
    namespace = {}
    exec(compile(code, "README.md", "exec"), namespace)  # its own asserts check the re-made result
    source, result = namespace["data"], namespace["result"]
    assert abs(result.num_vertices - 0.1 * len(source.vertices)) <= 0.01 * 0.1 * len(source.vertices) + 1
    assert result.stats.topology_kept
    assert namespace["fast"].parameters["mode"] == "fast" and namespace["guided"].parameters["mode"] == "quality"
    printed = capsys.readouterr().out.splitlines()
    assert printed[0] == f"{result.num_vertices} {result.num_triangles} True"
    assert re.fullmatch(r"max \d\.\d\d%, mean \d\.\d{3}% of the diagonal", printed[1])
    assert 0 < namespace["error"].symmetric.max < 0.05  # a tenth of the elephant stays within 5 %
