"""scripts/fetch_deps.py is the one fetcher of TetGen's sources and PHAT's headers: it refuses bytes
that do not match its pins, leaves a folder unpacked from the same pins as it is, and the zig
builds (scripts/zig_toolchain.sh: the Linux wheels, the macOS link) compile what it fetched, as the
cross builds and cibuildwheel do. No network: the downloads come from the cache the cross builds
fill (${TOPSTOC_CACHE}/deps-src/downloads); the tests that need them skip without it."""

import os
import pathlib
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "fetch_deps.py"
CACHED = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc")) / "deps-src" / "downloads"
ARCHIVES = ("tetgen_1.5.0.orig.tar.gz", "libphat-dev_1.6-2_all.deb")


def fetch(dest: pathlib.Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), str(dest)], capture_output=True, text=True, timeout=300)


@pytest.fixture
def downloads(tmp_path):
    """A destination folder whose downloads/ already holds both archives (copied from the cache)."""
    if not all((CACHED / name).exists() for name in ARCHIVES):
        pytest.skip(f"no cached downloads in {CACHED} (scripts/cross_build.sh fills it)")
    dest = tmp_path / "deps"
    (dest / "downloads").mkdir(parents=True)
    for name in ARCHIVES:
        shutil.copy(CACHED / name, dest / "downloads" / name)
    return dest


def test_a_download_that_does_not_match_its_pin_is_refused(tmp_path):
    dest = tmp_path / "deps"
    (dest / "downloads").mkdir(parents=True)
    (dest / "downloads" / "tetgen_1.5.0.orig.tar.gz").write_bytes(b"not the archive")
    done = fetch(dest)
    assert done.returncode != 0
    assert "tetgen_1.5.0.orig.tar.gz does not have the pinned SHA-256" in done.stderr
    assert not (dest / "tetgen" / "tetgen.cxx").exists() and not (dest / "pins").exists()


def test_unpacks_once_and_leaves_a_folder_of_the_same_pins_alone(downloads):
    assert fetch(downloads).returncode == 0
    for name in ("tetgen.cxx", "predicates.cxx", "tetgen.h", "LICENSE"):
        assert (downloads / "tetgen" / name).stat().st_size > 0
    assert (downloads / "phat/include/phat/boundary_matrix.h").exists()
    assert "4d114861d5ef2063afd06ef38885ec46822e90e7b4ea38c864f76493451f9cf3" in (downloads / "pins").read_text()
    marker = downloads / "tetgen" / "tetgen.h"
    marker.write_text("left alone")
    assert fetch(downloads).returncode == 0
    assert marker.read_text() == "left alone"
    (downloads / "pins").write_text("other pins\n")  # unpacked from other pins: unpacked anew
    assert fetch(downloads).returncode == 0
    assert marker.read_text() != "left alone"


def test_the_zig_builds_compile_what_fetch_deps_fetched(downloads, tmp_path):
    cache = tmp_path / "cache"
    cache.mkdir()
    downloads.rename(cache / "deps-src")
    shell = ('source scripts/zig_toolchain.sh && zig_cmake_args x86_64-linux-gnu.2.28 && '
             'printf "%s\\n" "${ZIG_CMAKE_ARGS[@]}"')
    done = subprocess.run(["bash", "-c", shell], cwd=ROOT, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "TOPSTOC_CACHE": str(cache), "ZIG": "/bin/false"})
    assert done.returncode == 0, done.stderr
    args = done.stdout.splitlines()
    assert f"-DTOPSTOC_TETGEN_SOURCE={cache}/deps-src/tetgen" in args
    assert f"-DPHAT_INCLUDE_DIR={cache}/deps-src/phat/include" in args
    assert (cache / "deps-src" / "tetgen" / "tetgen.cxx").exists()


def test_no_other_script_fetches_tetgen():
    files = [*ROOT.glob("scripts/*"), ROOT / "pyproject.toml", *ROOT.glob(".github/workflows/*")]
    fetching = [f.name for f in files if f.is_file() and f != SCRIPT
                and any(word in f.read_text(errors="replace") for word in ("tetgen_1.5.0", "pool/main/t/tetgen"))]
    assert fetching == []
