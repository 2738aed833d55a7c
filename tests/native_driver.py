"""The C++ command-line driver (native/tools/topstoc_decimate.cpp) as the tests run it: the Linux
build's, the Windows build's under Wine (tests/windows), and the cases both are compared on."""

import os
import pathlib
import subprocess

import numpy as np

from conftest import BUILD, DATA, ROOT

LINUX_DRIVER = BUILD / "topstoc_decimate"
WINDOWS_BUILD = pathlib.Path(os.environ.get("TOPSTOC_WINDOWS_BUILD", ROOT / "build-windows"))
WINDOWS_DRIVER = WINDOWS_BUILD / "topstoc_decimate.exe"
WINE = pathlib.Path("/usr/lib/wine/wine64")
CACHE = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc"))

#: (input, output format, arguments): every reader and writer, both modes, materials and open borders
CASES = [
    (DATA / "genus_positive" / "cgal_elephant.off", "obj", ["--vertices", "500", "--seed", "3", "--mode", "fast"]),
    (DATA / "genus_positive" / "cgal_elephant.off", "ply", ["--ratio", "0.2", "--seed", "7", "--mode", "quality"]),
    (DATA / "open_boundary" / "kivy_suzanne_monkey.obj", "off", ["--ratio", "0.3", "--seed", "1", "--mode", "quality"]),
    (DATA / "open_boundary" / "npm_teapot.obj", "obj", ["--ratio", "0.25", "--seed", "5", "--mode", "fast"]),
    (DATA / "genus0" / "cgal_fandisk.off", "stl", ["--ratio", "0.1", "--seed", "2", "--mode", "quality"]),
]


def wine_env() -> dict:
    """Wine with its own prefix in the cache (made on first use) and without its debug chatter."""
    return dict(os.environ, WINEPREFIX=str(CACHE / "wine-prefix"), WINEDEBUG="-all")


def run_driver(command: list, source: pathlib.Path, out: pathlib.Path, args: list, env=None):
    return subprocess.run([*map(str, command), str(source), str(out), *args], capture_output=True, text=True,
                          env=env, timeout=600)


def noisy_torus(path: pathlib.Path, nu: int = 480, nv: int = 260) -> pathlib.Path:
    """A 124,800-vertex torus with seeded noise, as binary PLY: big enough for the engine's
    parallel loops (kParallelMin = 100,000), irregular enough that ties in costs are rare."""
    from meshgen import torus
    from topstoc.core.io import MeshData, write_mesh

    vertices, triangles = torus(nu, nv)
    vertices = np.asarray(vertices, float) + np.random.default_rng(11).normal(0, 2e-3, (len(vertices), 3))
    write_mesh(path, MeshData(vertices=vertices, triangles=np.asarray(triangles, np.int32)))
    return path
