"""The C++ command-line driver (native/tools/topstoc_decimate.cpp) as the tests run it: this
machine's build, the cross builds (scripts/cross_build.sh) of Windows under Wine and of Linux
aarch64 under QEMU (tests/cross), and the cases they are compared on."""

import os
import pathlib
import subprocess

import numpy as np

from conftest import BUILD, DATA, ROOT

LINUX_DRIVER = BUILD / "topstoc_decimate"
CACHE = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc"))
WINE = pathlib.Path("/usr/lib/wine/wine64")
ARM64_ROOT = CACHE / "arm64-bookworm-root"  # scripts/arm64_root.sh

#: (input, output format, arguments): every reader and writer, both modes, materials and open borders
CASES = [
    (DATA / "genus_positive" / "cgal_elephant.off", "obj", ["--vertices", "500", "--seed", "3", "--mode", "fast"]),
    (DATA / "genus_positive" / "cgal_elephant.off", "ply", ["--ratio", "0.2", "--seed", "7", "--mode", "quality"]),
    (DATA / "open_boundary" / "kivy_suzanne_monkey.obj", "off", ["--ratio", "0.3", "--seed", "1", "--mode", "quality"]),
    (DATA / "open_boundary" / "npm_teapot.obj", "obj", ["--ratio", "0.25", "--seed", "5", "--mode", "fast"]),
    (DATA / "genus0" / "cgal_fandisk.off", "stl", ["--ratio", "0.1", "--seed", "2", "--mode", "quality"]),
]


def cross_runner(target: str):
    """(command prefix, environment, build folder) to run a cross build's programs here:
    Windows under Wine (its own prefix in the cache, no debug chatter); aarch64 under QEMU through
    binfmt_misc, its libraries from the arm64 root. None when this machine cannot run them."""
    build = ROOT / f"build-{target}"
    if target == "windows" and WINE.exists():
        return [WINE], dict(os.environ, WINEPREFIX=str(CACHE / "wine-prefix"), WINEDEBUG="-all"), build
    if target == "aarch64" and ARM64_ROOT.is_dir() and pathlib.Path("/proc/sys/fs/binfmt_misc/qemu-aarch64").exists():
        return [], dict(os.environ, QEMU_LD_PREFIX=str(ARM64_ROOT)), build
    return None


def run_driver(command: list, source: pathlib.Path, out: pathlib.Path, args: list, env=None):
    return subprocess.run([*map(str, command), str(source), str(out), *args], capture_output=True, text=True,
                          env=env, timeout=600)


def noisy_torus(path: pathlib.Path, nu: int = 480, nv: int = 260) -> pathlib.Path:
    """A 124,800-vertex torus with seeded noise, as binary PLY: big enough for the engine's
    parallel loops (kParallelMin = 100,000), irregular enough that ties in costs are rare."""
    from meshgen import torus
    from topstoc.core import MeshData, write_mesh

    vertices, triangles = torus(nu, nv)
    vertices = np.asarray(vertices, float) + np.random.default_rng(11).normal(0, 2e-3, (len(vertices), 3))
    write_mesh(path, MeshData(vertices=vertices, triangles=np.asarray(triangles, np.int32)))
    return path
