"""The cross builds (scripts/cross_build.sh) run where this machine can run them, against this
machine's Linux x86-64 build of the same sources: Windows x64 (mingw-w64, static) under Wine and
Linux aarch64 under QEMU user emulation. The command-line driver writes the same bytes for the
same input, target, seed and mode (binary files and text files alike: '\\n' line ends on Windows
too), and refuses to write over its input; Windows paths work; the doctest binaries hold the same
cases (scripts/windows_test.sh and scripts/aarch64_test.sh run them). Select one target with
-k windows or -k aarch64."""

import shutil
import subprocess

import pytest

from conftest import BUILD
from native_driver import CASES, LINUX_DRIVER, cross_runner, noisy_torus, run_driver

LINUX_TESTS = BUILD / "tests" / "native" / "topstoc_tests"
# Cases compiled only where fork() exists (tests/native/test_parallel.cpp).
POSIX_ONLY = {"a forked child makes a pool of its own instead of waiting for its parent's workers",
              "workers sleep between calls: serial gaps between parallel calls cost the process almost no CPU"}
EXE = {"windows": ".exe", "aarch64": ""}

if not LINUX_DRIVER.exists():
    pytest.skip(f"{LINUX_DRIVER} is not built", allow_module_level=True)


@pytest.fixture(params=["windows", "aarch64"])
def target(request):
    """(driver command, environment, build folder) of one cross build; skips when absent."""
    runner = cross_runner(request.param)
    if runner is None:
        pytest.skip(f"this machine cannot run {request.param} programs (Wine; QEMU with the arm64 root)")
    prefix, env, build = runner
    driver = build / f"topstoc_decimate{EXE[request.param]}"
    if not driver.exists():
        pytest.skip(f"{driver} is not built: run scripts/cross_build.sh {request.param}")
    return [*prefix, driver], env, build, request.param


def both(source, fmt, args, tmp_path, target):
    """This machine's and the cross build's output files for one case."""
    command, env, _, name = target
    native, cross = tmp_path / f"native.{fmt}", tmp_path / f"{name}.{fmt}"
    done = run_driver([LINUX_DRIVER], source, native, args)
    assert done.returncode == 0, done.stderr
    done = run_driver(command, source, cross, args, env=env)
    assert done.returncode == 0, done.stderr
    return native.read_bytes(), cross.read_bytes()


@pytest.mark.parametrize("source, fmt, args", CASES, ids=lambda c: getattr(c, "name", None))
def test_cross_driver_writes_the_same_bytes(tmp_path, target, source, fmt, args):
    native, cross = both(source, fmt, args, tmp_path, target)
    assert len(native) > 1000
    assert cross == native


@pytest.mark.parametrize("mode", ["fast", "quality"])
def test_cross_driver_matches_on_a_mesh_big_enough_for_threads(tmp_path, target, mode):
    source = noisy_torus(tmp_path / "torus.ply")
    native, cross = both(source, "obj", ["--ratio", "0.05", "--seed", "4", "--mode", mode], tmp_path, target)
    assert cross == native and b"\r" not in cross


def windows_path(path) -> str:
    """The path as a Windows program is given it: Wine's Z: drive is the Unix root."""
    return "Z:" + str(path).replace("/", "\\")


def test_cross_driver_keeps_its_input(tmp_path, data_dir, target):
    command, env, _, name = target
    source = tmp_path / "eight.off"
    shutil.copyfile(data_dir / "genus_positive" / "cgal_eight.off", source)
    before = source.read_bytes()
    # On Windows the same file is named two ways (Unix path in, Windows path out).
    same = windows_path(source) if name == "windows" else str(source)
    done = run_driver(command, source, same, ["--vertices", "60"], env=env)
    assert done.returncode == 1 and "is the input file" in done.stderr
    assert source.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["eight.off"]  # no .partial left


def test_windows_paths(tmp_path, data_dir):
    runner = cross_runner("windows")
    if runner is None or not (runner[2] / "topstoc_decimate.exe").exists():
        pytest.skip("needs Wine and the Windows build (scripts/cross_build.sh windows)")
    prefix, env, build = runner
    source, out, native = data_dir / "genus_positive" / "cgal_eight.off", tmp_path / "out.obj", tmp_path / "native.obj"
    done = subprocess.run([*map(str, prefix), str(build / "topstoc_decimate.exe"), windows_path(source),
                           windows_path(out), "--vertices", "60"], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    assert run_driver([LINUX_DRIVER], source, native, ["--vertices", "60"]).returncode == 0
    assert out.read_bytes() == native.read_bytes()


def test_cross_tests_hold_the_native_cases(target):
    command, env, build, name = target
    if not LINUX_TESTS.exists():
        pytest.skip(f"{LINUX_TESTS} is not built")
    listed = []
    for program, environment in (([LINUX_TESTS], None),
                                 ([*command[:-1], build / "tests" / "native" / f"topstoc_tests{EXE[name]}"], env)):
        done = subprocess.run([*map(str, program), "--list-test-cases", "--no-version"], capture_output=True,
                              text=True, env=environment, timeout=300)
        assert done.returncode == 0, done.stderr
        listed.append(sorted(line.strip() for line in done.stdout.splitlines()
                             if line.strip() and not line.startswith("[doctest]")))
    assert len(listed[0]) > 40
    expected = [case for case in listed[0] if name != "windows" or case not in POSIX_ONLY]
    assert listed[1] == expected
