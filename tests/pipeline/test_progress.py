"""``topstoc batch``'s progress as a user sees it: on a real terminal (a pseudo-terminal, with a
window size) a tqdm bar redrawn in place with carriage returns; with the output in a pipe or a
log, one plain line per asset and no carriage return; ``| tee log`` (standard error still a
terminal) gives the log its lines."""

import os
import re
import subprocess
import sys

import pytest

from assets import make_assets
from conftest import BUILD
from terminal import open_terminal, read_all

pytest.importorskip("tqdm")

ASSETS = 16
LINE = re.compile(r"topstoc batch \[(\d+)/(\d+)\] \S+: \d+ -> \d+ vertices, \d+ triangles")
BAR = re.compile(r"topstoc batch: +(\d+)%\|[^|\r\n]*\| (\d+)/(\d+) \[")


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """Assets that take a few seconds in all, so that the bar redraws several times."""
    return make_assets(tmp_path_factory.mktemp("library"), ASSETS, bases=("icosphere", "torus", "fandisk"),
                       levels=(1,))[0].parent


def _command(library, out, workers):
    return [sys.executable, "-m", "topstoc", "batch", "--input", str(library), "--output", str(out),
            "--ratio", "0.3", "--workers", str(workers)]


def _env():
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"), TERM="xterm")
    for name in ("COLUMNS", "LINES"):   # the width comes from the terminal itself
        env.pop(name, None)
    return env


def _carriage_returns(text: str) -> int:
    """Carriage returns that redraw a line (the terminal turns each newline into \\r\\n)."""
    return len(re.findall(r"\r(?!\n)", text))


@pytest.mark.parametrize("workers", [0, 2])
def test_a_terminal_gets_a_bar_redrawn_in_place(library, tmp_path, workers):
    if workers:
        pytest.importorskip("distributed")
    master, slave = open_terminal()
    try:
        process = subprocess.Popen(_command(library, tmp_path, workers), stdin=slave, stdout=slave, stderr=slave,
                                   env=_env(), close_fds=True)
        os.close(slave)
        text = read_all(master, process)
        assert process.wait(60) == 0, text
    finally:
        os.close(master)
    states = {(int(done), int(total)) for _, done, total in BAR.findall(text)}
    assert (0, ASSETS) in states and (ASSETS, ASSETS) in states, text
    assert len(states) >= 3, f"the bar was drawn only at {sorted(states)}"
    assert _carriage_returns(text) >= len(states) - 1, text
    assert not LINE.search(text), "per-asset lines on a terminal"
    assert "100%|" in text and f"topstoc batch: {ASSETS} done, 0 skipped, 0 failed" in text
    bars = [line for line in re.split(r"[\r\n]", text) if BAR.search(line)]
    assert max(map(len, bars)) <= 100, "the bar is wider than the terminal"


def test_a_pipe_gets_one_plain_line_per_asset(library, tmp_path):
    """(The Dask runner's lines in a pipe: test_batch_cluster.py.)"""
    done = subprocess.run(_command(library, tmp_path, 0), capture_output=True, text=True, env=_env(),
                          timeout=600)
    assert done.returncode == 0, done.stderr
    counts = [(int(i), int(n)) for i, n in LINE.findall(done.stdout)]
    assert sorted(counts) == [(i, ASSETS) for i in range(1, ASSETS + 1)]
    assert "\r" not in done.stdout + done.stderr and "%|" not in done.stdout + done.stderr


def test_output_to_a_log_with_the_terminal_on_standard_error(library, tmp_path):
    """``topstoc batch ... | tee log``: the log gets the lines; no bar mixes into the terminal."""
    master, slave = open_terminal()
    try:
        process = subprocess.Popen(_command(library, tmp_path, 0), stdin=slave, stdout=subprocess.PIPE,
                                   stderr=slave, env=_env(), close_fds=True)
        os.close(slave)
        log = process.stdout.read().decode()
        terminal = read_all(master, process)
        assert process.wait(60) == 0, terminal
    finally:
        os.close(master)
    assert len(LINE.findall(log)) == ASSETS
    assert "%|" not in terminal and _carriage_returns(terminal) == 0
