"""Runs a script under several thread counts (TOPSTOC_NUM_THREADS): results must not depend on the count."""

import os
import pathlib
import subprocess
import sys

import topstoc

BUILD = str(pathlib.Path(topstoc.__file__).resolve().parents[1])
TESTS = str(pathlib.Path(__file__).resolve().parent)


def outputs_by_thread_count(script: str, *args, counts=("1", "2", "3")) -> dict:
    """{thread count: stdout} of ``python -c script BUILD TESTS *args`` for each count."""
    outputs = {}
    for threads in counts:
        env = dict(os.environ, TOPSTOC_NUM_THREADS=threads)
        done = subprocess.run([sys.executable, "-c", script, BUILD, TESTS, *map(str, args)], env=env,
                              capture_output=True, text=True, check=True)
        outputs[threads] = done.stdout.strip()
    return outputs
