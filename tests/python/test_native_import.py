"""A failed import of the compiled module names the real cause (issue 15, item 5).

Each case builds a throw-away `topstoc` package (the staged Python sources without the compiled
module) in a temporary folder, adds a module file that cannot load for one reason, and imports
`topstoc.core.support.native` in a fresh interpreter.
"""

import importlib.machinery
import pathlib
import shutil
import subprocess
import sys
import sysconfig

import pytest

from conftest import BUILD, bare_env

STAGED = BUILD / "python" / "topstoc"
SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]  # e.g. .cpython-311-x86_64-linux-gnu.so
THIS = f"CPython {sys.version_info[0]}.{sys.version_info[1]}"
OTHER_MINOR = 13 if sys.version_info[:2] != (3, 13) else 11
MULTIARCH = sys.implementation._multiarch

# A valid extension module whose only flaw is a shared library that no longer exists.
FAKE_MODULE_C = """
#include <Python.h>
extern int topstoc_gone_answer(void);
static struct PyModuleDef def = {PyModuleDef_HEAD_INIT, "_topstoc", NULL, -1, NULL};
PyMODINIT_FUNC PyInit__topstoc(void) { topstoc_gone_answer(); return PyModule_Create(&def); }
"""


@pytest.fixture
def package(tmp_path) -> pathlib.Path:
    """tmp/topstoc: the staged sources, no compiled module."""
    shutil.copytree(STAGED, tmp_path / "topstoc",
                    ignore=shutil.ignore_patterns("_topstoc*", "__pycache__"))
    return tmp_path


def import_native(path: pathlib.Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "import topstoc.core.support.native as n; print(n.engine.__file__)"],
                          cwd=path, env=bare_env(PYTHONPATH=str(path), PATH="/usr/bin:/bin"),
                          capture_output=True, text=True, timeout=60)


def last_line(result) -> str:
    return result.stderr.strip().splitlines()[-1]


def compile_module_with_missing_library(directory: pathlib.Path) -> pathlib.Path:
    """Builds _topstoc<SUFFIX> in `directory` linked to libtopstoc_gone.so.1, then deletes the library."""
    gcc = shutil.which("gcc") or pytest.skip("no C compiler")
    work = directory / "cbuild"
    work.mkdir()
    (work / "gone.c").write_text("int topstoc_gone_answer(void) { return 42; }\n")
    (work / "module.c").write_text(FAKE_MODULE_C)
    subprocess.run([gcc, "-shared", "-fPIC", "-o", work / "libtopstoc_gone.so.1",
                    "-Wl,-soname,libtopstoc_gone.so.1", work / "gone.c"], check=True)
    module = directory / f"_topstoc{SUFFIX}"
    subprocess.run([gcc, "-shared", "-fPIC", "-I", sysconfig.get_paths()["include"], "-o", module,
                    work / "module.c", work / "libtopstoc_gone.so.1"], check=True)
    shutil.rmtree(work)
    return module


def test_no_module_says_not_installed(package):
    result = import_native(package)
    assert result.returncode != 0
    assert "_topstoc is not installed" in last_line(result)
    assert THIS in last_line(result)


def test_module_for_another_python_names_both_versions(package):
    (package / "topstoc" / f"_topstoc.cpython-3{OTHER_MINOR}-{MULTIARCH}.so").write_bytes(b"\x7fELF")
    message = last_line(import_native(package))
    assert f"is built for CPython 3.{OTHER_MINOR} ({MULTIARCH})" in message
    assert f"but this is {THIS} ({MULTIARCH})" in message


def test_module_for_another_platform_says_so(package):
    # A macOS build (suffix and Mach-O header) and a Linux name holding an aarch64 ELF binary.
    (package / "topstoc" / f"_topstoc.cpython-{sys.version_info[0]}{sys.version_info[1]}-darwin.so") \
        .write_bytes(b"\xcf\xfa\xed\xfe" + bytes(60))
    message = last_line(import_native(package))
    assert f"built for {THIS} (darwin)" in message and f"this is {THIS} ({MULTIARCH})" in message

    real = next(STAGED.glob("_topstoc*.so"))
    foreign = bytearray(real.read_bytes()[:4096])
    foreign[18:20] = (0xB7).to_bytes(2, "little")  # e_machine = AArch64
    (package / "topstoc" / f"_topstoc{SUFFIX}").write_bytes(bytes(foreign))
    message = last_line(import_native(package))
    assert "ELF aarch64 binary but this system loads ELF x86_64 (wrong platform)" in message


def test_missing_library_is_named(package):
    compile_module_with_missing_library(package / "topstoc")
    result = import_native(package)
    assert result.returncode != 0
    message = last_line(result)
    assert "the library libtopstoc_gone.so.1 it needs is missing" in message
    assert "built for" not in message  # not blamed on the Python version


def test_missing_library_in_native_distribution_is_named(package):
    """The extension layout: the add-on holds no binary, topstoc_native does."""
    native = package / "topstoc_native"
    native.mkdir()
    (native / "__init__.py").write_text("")
    compile_module_with_missing_library(native)
    message = last_line(import_native(package))
    assert "topstoc_native" in message and "libtopstoc_gone.so.1 it needs is missing" in message


def test_native_distribution_is_loaded_when_package_has_no_module(package):
    native = package / "topstoc_native"
    native.mkdir()
    (native / "__init__.py").write_text("")
    shutil.copy(next(STAGED.glob("_topstoc*.so")), native)
    result = import_native(package)
    assert result.returncode == 0, result.stderr
    assert pathlib.Path(result.stdout.strip()).parent == native
