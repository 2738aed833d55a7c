#!/usr/bin/env python3
"""Fetches the engine's two third-party sources from Debian, checked against pinned SHA-256s:

    python3 scripts/fetch_deps.py DEST

DEST/tetgen  TetGen 1.5.0 (tetgen.cxx, predicates.cxx, tetgen.h, LICENSE) from Debian's source
             package (tetgen_1.5.0.orig.tar.gz; Debian's two patches touch only its build files)
DEST/phat    PHAT 1.6's headers (include/phat/...) from Debian's arch-independent libphat-dev
             package (header-only; its orig tarball is not on the mirror)

The one fetcher of these sources for every build that does not use the host's packages: the
zig builds (scripts/zig_toolchain.sh: the Linux wheels and the macOS link) compile DEST/tetgen into
the module, the cross builds (scripts/cross_build.sh) and cibuildwheel's before-all step on every
hosted runner (Windows included) build it as a static library with cmake/deps/CMakeLists.txt.
Plain Python (urllib, tarfile), so that all of them get the same bytes. Downloads are kept in
DEST/downloads; a DEST already unpacked from the same pins is left as it is.
"""

import hashlib
import io
import pathlib
import shutil
import sys
import tarfile
import urllib.request

MIRROR = "https://deb.debian.org/debian/pool/main"
TETGEN = ("t/tetgen/tetgen_1.5.0.orig.tar.gz", "4d114861d5ef2063afd06ef38885ec46822e90e7b4ea38c864f76493451f9cf3")
PHAT = ("p/phat/libphat-dev_1.6-2_all.deb", "87b276b57a4267f4a5f91f8a98dfd23bf4ca99f429a2586e3379508df7223a0d")
TETGEN_FILES = ("tetgen.cxx", "predicates.cxx", "tetgen.h", "LICENSE")
PINS = f"{TETGEN[1]} {TETGEN[0]}\n{PHAT[1]} {PHAT[0]}\n"  # written to DEST/pins once unpacked


def download(path: str, sha256: str, downloads: pathlib.Path) -> bytes:
    """The file's bytes, from the cache or the mirror; a wrong checksum is an error either way."""
    local = downloads / path.rsplit("/", 1)[1]
    if local.exists():
        data = local.read_bytes()
    else:
        with urllib.request.urlopen(f"{MIRROR}/{path}", timeout=120) as response:
            data = response.read()
    if hashlib.sha256(data).hexdigest() != sha256:
        sys.exit(f"error: {local.name} does not have the pinned SHA-256 {sha256}")
    if not local.exists():
        downloads.mkdir(parents=True, exist_ok=True)
        partial = local.with_suffix(".partial")
        partial.write_bytes(data)
        partial.replace(local)
    return data


def ar_member(deb: bytes, prefix: str) -> bytes:
    """A member of a .deb (an ar archive) whose name starts with prefix."""
    assert deb[:8] == b"!<arch>\n", "not a .deb"
    at = 8
    while at + 60 <= len(deb):
        name, size = deb[at:at + 16].decode().strip(), int(deb[at + 48:at + 58])
        if name.startswith(prefix):
            return deb[at + 60:at + 60 + size]
        at += 60 + size + size % 2
    raise ValueError(f"no {prefix}* in the .deb")


def extract(archive: tarfile.TarFile, take, dest: pathlib.Path) -> None:
    """Writes the regular files for which take(name) gives a relative path into dest."""
    for member in archive.getmembers():
        relative = take(member.name) if member.isfile() else None
        if relative:
            target = dest / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(archive.extractfile(member).read())


def unpacked(dest: pathlib.Path) -> bool:
    """Whether dest holds every file, unpacked from the current pins."""
    stamp = dest / "pins"
    return (stamp.exists() and stamp.read_text() == PINS
            and all((dest / "tetgen" / f).exists() for f in TETGEN_FILES)
            and (dest / "phat/include/phat/boundary_matrix.h").exists())


def main() -> None:
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    dest = pathlib.Path(sys.argv[1]).resolve()
    if unpacked(dest):
        print(dest)
        return
    downloads = dest / "downloads"
    (dest / "pins").unlink(missing_ok=True)
    for name in ("tetgen", "phat"):
        shutil.rmtree(dest / name, ignore_errors=True)
    with tarfile.open(fileobj=io.BytesIO(download(*TETGEN, downloads)), mode="r:gz") as archive:
        extract(archive, lambda n: n.split("/", 1)[1] if n.split("/", 1)[-1] in TETGEN_FILES else None,
                dest / "tetgen")
    data = ar_member(download(*PHAT, downloads), "data.tar")
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:*") as archive:
        extract(archive, lambda n: n.split("usr/", 1)[1] if "usr/include/phat/" in n else None, dest / "phat")
    missing = [f for f in TETGEN_FILES if not (dest / "tetgen" / f).exists()]
    if missing or not (dest / "phat/include/phat/boundary_matrix.h").exists():
        sys.exit(f"error: the archives lack {missing or 'phat/boundary_matrix.h'}")
    (dest / "pins.partial").write_text(PINS)
    (dest / "pins.partial").replace(dest / "pins")
    print(dest)


if __name__ == "__main__":
    main()
