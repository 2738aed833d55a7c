"""The Windows x64 build (scripts/windows_build.sh: mingw-w64, static) under Wine, against the
Linux build of the same sources: the command-line driver writes the same bytes for the same input,
target, seed and mode (binary files and text files alike: '\\n' line ends on Windows too), reads
Windows paths, and refuses to write over its input; the doctest binary holds the same cases as
the Linux one (scripts/windows_test.sh runs them). Run by scripts/windows_test.sh."""

import shutil
import subprocess

import pytest

from conftest import BUILD
from native_driver import CASES, LINUX_DRIVER, WINDOWS_BUILD, WINDOWS_DRIVER, WINE, noisy_torus, run_driver, wine_env

WINDOWS_TESTS = WINDOWS_BUILD / "tests" / "native" / "topstoc_tests.exe"
LINUX_TESTS = BUILD / "tests" / "native" / "topstoc_tests"

if not WINE.exists() or not WINDOWS_DRIVER.exists():
    pytest.skip("needs Wine and the Windows build: run scripts/windows_build.sh", allow_module_level=True)
if not LINUX_DRIVER.exists():
    pytest.skip(f"{LINUX_DRIVER} is not built", allow_module_level=True)

WINDOWS = [WINE, WINDOWS_DRIVER]


def windows_path(path) -> str:
    """The path as a Windows program is given it: Wine's Z: drive is the Unix root."""
    return "Z:" + str(path).replace("/", "\\")


def both(source, fmt, args, tmp_path):
    """The Linux and the Windows driver's output files for one case."""
    linux, windows = tmp_path / f"linux.{fmt}", tmp_path / f"windows.{fmt}"
    done = run_driver([LINUX_DRIVER], source, linux, args)
    assert done.returncode == 0, done.stderr
    done = run_driver(WINDOWS, source, windows, args, env=wine_env())
    assert done.returncode == 0, done.stderr
    return linux.read_bytes(), windows.read_bytes()


@pytest.mark.parametrize("source, fmt, args", CASES, ids=lambda c: getattr(c, "name", None))
def test_windows_driver_writes_the_linux_bytes(tmp_path, source, fmt, args):
    linux, windows = both(source, fmt, args, tmp_path)
    assert len(linux) > 1000
    assert windows == linux


@pytest.mark.parametrize("mode", ["fast", "quality"])
def test_windows_driver_matches_on_a_mesh_big_enough_for_threads(tmp_path, mode):
    source = noisy_torus(tmp_path / "torus.ply")
    linux, windows = both(source, "obj", ["--ratio", "0.05", "--seed", "4", "--mode", mode], tmp_path)
    assert windows == linux and b"\r" not in windows


def test_windows_paths_and_the_input_kept(tmp_path, data_dir):
    source = tmp_path / "eight.off"
    shutil.copyfile(data_dir / "genus_positive" / "cgal_eight.off", source)
    before = source.read_bytes()
    out = tmp_path / "out.obj"
    done = subprocess.run([*map(str, WINDOWS), windows_path(source), windows_path(out), "--vertices", "60"],
                          capture_output=True, text=True, env=wine_env(), timeout=300)
    assert done.returncode == 0, done.stderr
    linux = tmp_path / "linux.obj"
    assert run_driver([LINUX_DRIVER], source, linux, ["--vertices", "60"]).returncode == 0
    assert out.read_bytes() == linux.read_bytes()
    # The same file named two ways (Unix path in, Windows path out) is still the input.
    done = run_driver(WINDOWS, source, windows_path(source), ["--vertices", "60"], env=wine_env())
    assert done.returncode == 1 and "is the input file" in done.stderr
    assert source.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["eight.off", "linux.obj", "out.obj"]


def test_windows_tests_hold_the_linux_cases():
    if not LINUX_TESTS.exists():
        pytest.skip(f"{LINUX_TESTS} is not built")
    listed = []
    for command, env in (([LINUX_TESTS], None), ([WINE, WINDOWS_TESTS], wine_env())):
        done = subprocess.run([*map(str, command), "--list-test-cases", "--no-version"], capture_output=True,
                              text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr
        listed.append(sorted(line.strip() for line in done.stdout.splitlines() if line.strip()))
    assert len(listed[0]) > 40
    assert listed[1] == listed[0]
