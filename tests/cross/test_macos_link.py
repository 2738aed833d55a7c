"""The macOS modules linked by scripts/build_macos.sh (zig's clang and libc++) are what a macOS
CPython loads: 64-bit Mach-O dynamic libraries (MH_DYLIB: zig 0.15's linker crashes on -bundle,
cmake/zig_macos_rules.cmake; dlopen loads either) for arm64 and x86_64, macOS 11 or older as minimum, linking
only the system's libSystem (libc++ and TetGen are inside), exporting PyInit__topstoc and leaving
CPython's symbols to the interpreter (`-undefined dynamic_lookup`). Parsed here from the Mach-O
header, load commands and symbol table, no macOS tool needed.
"""

import pathlib
import struct

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CPU_TYPE = {"aarch64": 0x0100000C, "x86_64": 0x01000007}  # CPU_TYPE_ARM64, CPU_TYPE_X86_64
MH_MAGIC_64, MH_DYLIB = 0xFEEDFACF, 6
LC_SYMTAB, LC_LOAD_DYLIB, LC_BUILD_VERSION = 0x2, 0xC, 0x32
PLATFORM_MACOS = 1


def parse(data: bytes) -> dict:
    """Header fields, linked dylibs, minimum macOS and the defined and undefined external symbols."""
    magic, cputype, _, filetype, ncmds, _, _, _ = struct.unpack_from("<8I", data, 0)
    out = dict(magic=magic, cputype=cputype, filetype=filetype, dylibs=[], platform=None, minos=None)
    offset = 32
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<2I", data, offset)
        if cmd == LC_LOAD_DYLIB:
            name_offset = struct.unpack_from("<I", data, offset + 8)[0]
            out["dylibs"].append(data[offset + name_offset:offset + size].split(b"\0")[0].decode())
        elif cmd == LC_BUILD_VERSION:
            platform, minos = struct.unpack_from("<2I", data, offset + 8)
            out["platform"], out["minos"] = platform, (minos >> 16, (minos >> 8) & 0xFF)
        elif cmd == LC_SYMTAB:
            symoff, nsyms, stroff, _ = struct.unpack_from("<4I", data, offset + 8)
            defined, undefined = set(), set()
            for i in range(nsyms):
                strx, ntype, _, _, _ = struct.unpack_from("<IBBHQ", data, symoff + 16 * i)
                if ntype & 0xE0 or not ntype & 1:  # debugging entries; local symbols
                    continue
                name = data[stroff + strx:data.index(b"\0", stroff + strx)].decode()
                (undefined if ntype & 0xE == 0 else defined).add(name)
            out["defined"], out["undefined"] = defined, undefined
        offset += size
    return out


@pytest.mark.parametrize("arch", ["aarch64", "x86_64"])
def test_macos_module_is_a_dylib_for_its_arch_linking_only_libsystem(arch):
    module = ROOT / "build" / f"macos-{arch}" / "python" / "topstoc" / "_topstoc.cpython-311-darwin.so"
    if not module.exists():
        pytest.skip(f"{module.relative_to(ROOT)} not built: run scripts/build_macos.sh")
    info = parse(module.read_bytes())
    assert info["magic"] == MH_MAGIC_64 and info["filetype"] == MH_DYLIB
    assert info["cputype"] == CPU_TYPE[arch]
    assert info["platform"] == PLATFORM_MACOS and info["minos"] <= (11, 0)
    assert info["dylibs"] == ["/usr/lib/libSystem.B.dylib"], info["dylibs"]
    assert "_PyInit__topstoc" in info["defined"]
    # CPython's API is resolved when the interpreter loads the bundle.
    assert any(name.startswith("_Py") for name in info["undefined"]), sorted(info["undefined"])[:20]
