"""The C++ command-line driver (build/topstoc_decimate): the same file as the Python CLI for the
same input, target, seed and mode (an independent path: Python reads, prepares, calls the engine
and writes there), clear refusals, and the input never written over. Its Windows build is
compared with it under Wine (tests/cross)."""

import pytest

import cli
from native_driver import CASES, LINUX_DRIVER, run_driver

if not LINUX_DRIVER.exists():
    pytest.skip(f"{LINUX_DRIVER} is not built (TOPSTOC_TOOLS=OFF)", allow_module_level=True)


@pytest.mark.parametrize("source, fmt, args", CASES, ids=lambda c: getattr(c, "name", None))
def test_driver_writes_what_the_python_cli_writes(tmp_path, source, fmt, args):
    native, python = tmp_path / f"native.{fmt}", tmp_path / f"python.{fmt}"
    done = run_driver([LINUX_DRIVER], source, native, args)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert done.stdout.startswith(f"{source}: ") and f" -> {native}: " in done.stdout  # one summary line
    reference = cli.run("decimate", source, python, *args)
    assert reference.returncode == 0, reference.stderr
    assert native.read_bytes() == python.read_bytes()


@pytest.mark.parametrize("args, message", [
    ([], "give one target"),
    (["--vertices", "10", "--ratio", "0.5"], "give one target"),
    (["--ratio", "1.5"], "the target must lie in"),
    (["--vertices", "-3"], "--vertices needs a non-negative number, got '-3'"),
    (["--vertices", "12x"], "--vertices needs a non-negative number, got '12x'"),
    (["--vertices", "10", "--mode", "finest"], "--mode must be fast, quality or best, got 'finest'"),
    (["--vertices", "10", "--colour"], "unknown option --colour"),
    (["--vertices"], "--vertices needs a value"),
])
def test_usage_errors_are_one_line_and_exit_2(tmp_path, data_dir, args, message):
    out = tmp_path / "out.obj"
    done = run_driver([LINUX_DRIVER], data_dir / "genus_positive" / "cgal_eight.off", out, args)
    assert done.returncode == 2
    first, usage = done.stderr.splitlines()
    assert first.startswith(f"topstoc_decimate: error: {message}")
    assert usage.startswith("usage: topstoc_decimate IN OUT")
    assert not out.exists() and done.stdout == ""


def test_bad_input_and_bad_output_name_are_reported(tmp_path, data_dir):
    broken = tmp_path / "broken.off"
    broken.write_bytes(b"OFF\n3 1 0\n0 0 0\n1 0 0\n")
    done = run_driver([LINUX_DRIVER], broken, tmp_path / "out.obj", ["--vertices", "3"])
    assert done.returncode == 1
    assert done.stderr.startswith(f"topstoc_decimate: error: {broken}: ") and len(done.stderr.splitlines()) == 1
    done = run_driver([LINUX_DRIVER], data_dir / "genus_positive" / "cgal_eight.off", tmp_path / "out.xyz",
                      ["--vertices", "30"])
    assert done.returncode == 1 and "xyz" in done.stderr and not (tmp_path / "out.xyz").exists()


def test_the_input_is_never_written_over(tmp_path, data_dir):
    source = tmp_path / "eight.off"
    source.write_bytes((data_dir / "genus_positive" / "cgal_eight.off").read_bytes())
    before = source.read_bytes()
    alias = tmp_path / "alias.off"
    alias.symlink_to(source)
    for target in (source, alias):
        done = run_driver([LINUX_DRIVER], source, target, ["--vertices", "50"])
        assert done.returncode == 1
        assert "is the input file" in done.stderr
    assert source.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["alias.off", "eight.off"]  # no .partial left
