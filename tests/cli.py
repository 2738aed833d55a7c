"""Runs ``python -m topstoc COMMAND ...`` in a subprocess, as a user would, against the build
under test (TOPSTOC_BUILD or build/)."""

import json
import os
import subprocess
import sys

from conftest import BUILD


def run(command, *args, timeout=300):
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    return subprocess.run([sys.executable, "-m", "topstoc", command, *map(str, args)],
                          capture_output=True, text=True, env=env, timeout=timeout)


def run_json(command, *args):
    """The --json report of a run that must succeed silently."""
    done = run(command, *args, "--json")
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    return json.loads(done.stdout)


def assert_one_error_line(command, done, *fragments):
    """Failed with exit 1 and one line on stderr naming the command and every fragment."""
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith(f"topstoc {command}: error: ")
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert done.stdout == ""
