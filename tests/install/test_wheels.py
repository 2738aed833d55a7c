"""The Linux wheels in dist/ (scripts/build_wheels.sh) hold what their tags promise (issue 41).

For each of the eight wheels ({topstoc, topstoc_native} x {cp311, cp313} x {x86_64, aarch64}):
the tag says manylinux_2_28 or lower, `auditwheel show` agrees, and the module inside is an ELF
file for the tag's machine that needs glibc alone (libc++ and TetGen are linked in), with no
symbol version newer than glibc 2.28 and none of libstdc++ (read with binutils' readelf, which
reads every architecture's ELF).
"""

import os
import pathlib
import re
import subprocess
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DIST = ROOT / "dist"
AUDITWHEEL = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc")) / "wheel-venv" / "bin" / "auditwheel"
ELF_MACHINE = {"x86_64": "Advanced Micro Devices X86-64", "aarch64": "AArch64"}
GLIBC_ONLY = re.compile(r"(libc|libm|libpthread|libdl|librt)\.so\.\d+|ld-linux-(x86-64|aarch64)\.so\.\d+")
WHEEL = re.compile(r"(?P<dist>topstoc|topstoc_native)-[^-]+-(?P<py>cp3\d+)-(?P=py)-"
                   r"manylinux_2_(?P<glibc>\d+)_(?P<arch>x86_64|aarch64)\.whl")

WHEELS = sorted(DIST.glob("*.whl"))
if not WHEELS:
    pytest.skip("no wheels in dist/: run scripts/build_wheels.sh", allow_module_level=True)


def test_dist_holds_both_distributions_for_both_pythons_and_architectures():
    found = sorted((m["dist"], m["py"], m["arch"]) for m in map(WHEEL.fullmatch, (w.name for w in WHEELS)) if m)
    assert len(found) == len(WHEELS), [w.name for w in WHEELS]
    assert found == sorted((d, p, a) for d in ("topstoc", "topstoc_native") for p in ("cp311", "cp313")
                           for a in ("x86_64", "aarch64"))


def readelf(*args) -> str:
    return subprocess.run(["readelf", "-W", *args], capture_output=True, text=True, check=True).stdout


@pytest.mark.parametrize("wheel", WHEELS, ids=lambda w: w.name)
def test_wheel_needs_glibc_2_28_at_most(wheel, tmp_path):
    tag = WHEEL.fullmatch(wheel.name)
    assert tag and int(tag["glibc"]) <= 28, wheel.name
    with zipfile.ZipFile(wheel) as archive:
        modules = [n for n in archive.namelist() if n.endswith(".so") or ".so." in n]
        assert len(modules) == 1, modules  # the module alone: nothing bundled beside it
        module = pathlib.Path(archive.extract(modules[0], tmp_path))
    assert module.name == f"_topstoc.cpython-{tag['py'][2:]}-{tag['arch']}-linux-gnu.so"
    assert ELF_MACHINE[tag["arch"]] in readelf("-h", str(module))
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.+?)\]", readelf("-d", str(module)))
    assert needed and all(GLIBC_ONLY.fullmatch(n) for n in needed), needed
    versions = set(re.findall(r"@(GLIBC[A-Z]*)_([\d.]+)", readelf("--dyn-syms", str(module))))
    assert versions and {name for name, _ in versions} == {"GLIBC"}, versions  # no GLIBCXX, CXXABI
    newest = max(tuple(map(int, v.split("."))) for _, v in versions)
    assert newest <= (2, 28), newest
    shown = subprocess.run([str(AUDITWHEEL), "-v", "show", str(wheel)], capture_output=True, text=True, check=True).stdout
    shown = " ".join(shown.split())  # auditwheel wraps its lines
    assert "requires no external shared libraries" in shown, shown
    consistent = re.search(r'consistent with the following platform tag:\s*"manylinux_2_(\d+)_(\w+)"', shown)
    assert consistent and int(consistent[1]) <= 28 and consistent[2] == tag["arch"], shown
