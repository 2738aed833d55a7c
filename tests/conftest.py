"""Shared test setup: finds the staged package (build/python) and the test meshes."""

import os
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))
DATA = ROOT / "tests" / "data"
SHARED_MESHES = ROOT.parent / "shared" / "meshes"

for path in (str(BUILD / "python"), str(ROOT / "tests")):
    if path not in sys.path:
        sys.path.insert(0, path)

#: What a sanitizer build needs in every process that loads the module (scripts/sanitize.sh).
SANITIZER_VARIABLES = ("LD_PRELOAD", "ASAN_OPTIONS", "UBSAN_OPTIONS")


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "heavy: a long engine check; the suites repeated for another NumPy or Blender, "
        "which test the interface, skip it (-m 'not heavy'), the first suite runs it")


def bare_env(**variables) -> dict:
    """An environment of just ``variables`` for a subprocess, plus the sanitizer runtime's
    variables when they are set (without them an ASan build cannot load)."""
    env = {name: os.environ[name] for name in SANITIZER_VARIABLES if name in os.environ}
    env.update(variables)
    return env


@pytest.fixture(scope="session")
def data_dir() -> pathlib.Path:
    return DATA


@pytest.fixture(scope="session")
def shared_meshes() -> pathlib.Path:
    """../shared/meshes when present (benchmarks and extra checks); skips otherwise."""
    if not SHARED_MESHES.is_dir():
        pytest.skip("../shared/meshes is not available")
    return SHARED_MESHES
