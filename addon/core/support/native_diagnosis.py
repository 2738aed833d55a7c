"""Says in one sentence why the compiled module `_topstoc` could not be imported.

Python's own message is often misleading: an extension built for another CPython is simply
"not found", and a missing shared library shows up as an OSError text deep in a chained
exception. This module looks at the candidate files themselves (their extension suffix and ELF
header) and at the loader's error text, and names the real cause: no module, a missing library,
the wrong Python, the wrong platform.
"""

from __future__ import annotations

import importlib.machinery
import os
import platform
import re
import sys

MODULE = "_topstoc"

# .cpython-311-x86_64-linux-gnu.so, .cpython-313-darwin.so, .cp311-win_amd64.pyd, .abi3.so
_SUFFIX = re.compile(r"^_topstoc\.(?:cpython-(?P<cpython>\d)(?P<minor>\d+)[a-z]*(?:-(?P<platform>[\w-]+))?"
                     r"|cp(?P<cp_major>\d)(?P<cp_minor>\d+)-(?P<win_platform>\w+)|abi3)\.(?:so|pyd)$")
_MISSING_LIBRARY = re.compile(r"([^\s:]+): cannot open shared object file")
_MISSING_VERSION = re.compile(r"version [`'](\S+?)' not found \(required by ([^)]+)\)")
_UNDEFINED_SYMBOL = re.compile(r"undefined symbol: (\S+)")

# ELF e_machine values for the machines Blender ships on.
_ELF_MACHINES = {0x3E: "x86_64", 0xB7: "aarch64", 0x03: "i386", 0x28: "arm"}


def this_python() -> str:
    """'CPython 3.13 (x86_64-linux-gnu)': the running interpreter as module suffixes name it."""
    multiarch = getattr(sys.implementation, "_multiarch", None) or f"{sys.platform}-{platform.machine()}"
    return f"{platform.python_implementation()} {sys.version_info[0]}.{sys.version_info[1]} ({multiarch})"


def candidate_files(directories) -> list[str]:
    """Every file in the given directories that looks like a build of the module."""
    found = []
    for directory in directories:
        try:
            names = sorted(os.listdir(directory))
        except OSError:
            continue
        found += [os.path.join(directory, n) for n in names
                  if n.startswith(MODULE + ".") and n.endswith((".so", ".pyd"))]
    return found


def built_for(path: str) -> str | None:
    """'CPython 3.11 (x86_64-linux-gnu)' read from a module file's suffix (None if unknown)."""
    match = _SUFFIX.match(os.path.basename(path))
    if not match:
        return None
    if match["cpython"]:
        where = f" ({match['platform']})" if match["platform"] else ""
        return f"CPython {match['cpython']}.{match['minor']}{where}"
    if match["cp_major"]:
        return f"CPython {match['cp_major']}.{match['cp_minor']} ({match['win_platform']})"
    return "the stable ABI (abi3)"


def binary_format(path: str) -> str | None:
    """The file's binary format and machine ('ELF x86_64', 'Mach-O', 'PE'), None if unreadable."""
    try:
        with open(path, "rb") as f:
            head = f.read(20)
    except OSError:
        return None
    if head[:4] == b"\x7fELF" and len(head) >= 20:
        little = head[5] == 1
        machine = int.from_bytes(head[18:20], "little" if little else "big")
        return f"ELF {_ELF_MACHINES.get(machine, hex(machine))}"
    if head[:4] in (b"\xcf\xfa\xed\xfe", b"\xce\xfa\xed\xfe", b"\xca\xfe\xba\xbe"):
        return "Mach-O"
    if head[:2] == b"MZ":
        return "PE"
    return "unknown"


def this_binary_format() -> str:
    """The binary format this Python loads ('ELF x86_64' on Linux x86-64)."""
    if sys.platform.startswith("linux"):
        machine = platform.machine()
        return f"ELF {'x86_64' if machine in ('x86_64', 'AMD64') else machine}"
    return {"darwin": "Mach-O", "win32": "PE"}.get(sys.platform, sys.platform)


def loader_cause(error: BaseException) -> str | None:
    """The cause named in a loader message (dlopen/LoadLibrary) anywhere in an exception chain."""
    seen = set()
    while error is not None and id(error) not in seen:
        seen.add(id(error))
        text = str(error)
        if match := _MISSING_LIBRARY.search(text):
            return f"the library {match[1]} it needs is missing (not bundled, not installed on this system)"
        if match := _MISSING_VERSION.search(text):
            libc = " ".join(platform.libc_ver()) or "unknown"
            return (f"{os.path.basename(match[2])} needs {match[1]}, newer than this system provides "
                    f"(C library: {libc})")
        if match := _UNDEFINED_SYMBOL.search(text):
            return (f"a symbol is missing ({match[1]}): the module and the libraries it found do not "
                    f"match (mixed builds or a wrong library on the search path)")
        if "wrong ELF class" in text or "invalid ELF header" in text or "not a valid Win32" in text:
            return f"it is not a binary for this platform ({text.strip()})"
        error = error.__cause__ or error.__context__
    return None


def explain(error: BaseException, directories) -> str:
    """One message naming why `_topstoc` did not import from `directories` (searched in order)."""
    files = candidate_files(directories)
    where = " or ".join(directories)
    if not files:
        return (f"topstoc's compiled module {MODULE} is not installed (looked in {where}); "
                f"install the wheel or extension for {this_python()}, or build it with "
                f"'cmake -S . -B build && cmake --build build' and use build/python/topstoc")
    # The names this interpreter would import (the bare ".so" suffix too: `_topstoc.so`).
    names = {MODULE + suffix for suffix in importlib.machinery.EXTENSION_SUFFIXES}
    loadable = [f for f in files if os.path.basename(f) in names]
    if loadable:
        path = loadable[0]
        fmt, expected = binary_format(path), this_binary_format()
        # A binary for another machine first: the loader then reports the module itself "missing".
        if fmt and fmt != expected:
            cause = f"it is a {fmt} binary but this system loads {expected} (wrong platform)"
        else:
            cause = loader_cause(error)
        if cause is None:
            cause = f"{type(error).__name__}: {str(error).strip() or 'no details'}"
        return f"topstoc's compiled module {path} could not be loaded: {cause}"
    # Files exist but none carries a suffix this interpreter loads: another Python or platform.
    described = "; ".join(f"{os.path.basename(f)} is built for {built_for(f) or 'an unknown Python'}"
                          for f in files)
    return (f"topstoc's compiled module does not match this Python: {described}, but this is "
            f"{this_python()}. Install the wheel or extension built for {this_python()}")
