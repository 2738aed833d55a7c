"""Checks an installed topstoc wheel where it was installed, with nothing of a checkout on the path:

    python wheel_check.py [MESH]
    python wheel_check.py --native [MESH]   the topstoc_native wheel, as the Blender extension uses it

--native: the add-on's sources (this checkout's addon/, copied as the extension holds them: no
binary inside) must load the engine from the installed `topstoc_native`, and no `topstoc`
distribution may be installed beside it; then the same decimations.

Run by cibuildwheel's test-command on every hosted runner (pyproject.toml) and by the Linux aarch64
suite under QEMU (scripts/aarch64_test.sh). `topstoc` must import from site-packages with its
compiled module; `python -m topstoc decimate` (the installed CLI) on a closed genus-2 mesh, in
both modes, must report the topology kept and write a closed triangle mesh with the input's Euler
characteristic and the asked vertex count (fast mode: every output vertex an input vertex). Prints
one line per run with the output's SHA-256, which runners can be compared by. Exit code 0 only if
every check held. Plain Python: no pytest, no conftest putting a build tree on sys.path.
"""

import hashlib
import importlib.util
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
MESH = HERE.parent / "data" / "genus_positive" / "cgal_eight.off"  # 315 vertices, genus 2
RATIO = 0.3


def euler(vertices: np.ndarray, triangles: np.ndarray) -> tuple:
    """(V - E + F, closed): closed when every edge has exactly two triangles."""
    edges = np.sort(triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return len(vertices) - len(counts) + len(triangles), bool(np.all(counts == 2))


def check_import() -> None:
    import importlib

    import topstoc

    engine = importlib.import_module("topstoc._topstoc")  # the compiled module, in every layout
    for module in (topstoc, engine):
        location = pathlib.Path(module.__file__).resolve()
        assert "site-packages" in location.parts, f"{module.__name__} comes from {location}, not an install"
    print(f"imported {engine.__name__} from {engine.__file__}")


def use_extension_layout(work: pathlib.Path) -> dict:
    """Puts a copy of addon/ on the path as `topstoc` (the extension's add-on package, no binary)
    and checks that its engine is the installed topstoc_native's; returns the environment that
    gives child processes the same path."""
    assert importlib.util.find_spec("topstoc") is None, "a topstoc package is installed beside topstoc_native"
    shutil.copytree(HERE.parents[1] / "addon", work / "topstoc", ignore=shutil.ignore_patterns("__pycache__"))
    assert not list((work / "topstoc").glob("_topstoc*")), "addon/ holds a compiled module"
    sys.path.insert(0, str(work))
    from topstoc.core.support.native import engine

    location = pathlib.Path(engine.__file__).resolve()
    assert engine.__name__ == "topstoc_native._topstoc" and "site-packages" in location.parts, location
    print(f"the add-on loaded {engine.__name__} from {engine.__file__}")
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(work), os.environ.get("PYTHONPATH", "")]))


def check_decimation(mesh: pathlib.Path, mode: str, work: pathlib.Path, env=None) -> None:
    from topstoc.core import read_mesh

    out = work / f"{mode}.obj"
    done = subprocess.run([sys.executable, "-m", "topstoc", "decimate", str(mesh), str(out), "--ratio", str(RATIO),
                           "--seed", "1", "--mode", mode, "--json"], capture_output=True, text=True, timeout=600,
                          env=env)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    source, result = read_mesh(mesh), read_mesh(out)
    assert report["topology_kept"] is True, report
    assert report["output"]["vertices"] == len(result.vertices)
    want = round(RATIO * len(source.vertices))
    assert abs(len(result.vertices) - want) <= 1 + report["repairs"], (len(result.vertices), want)
    chi_in, closed_in = euler(source.vertices, source.triangles)
    chi_out, closed_out = euler(result.vertices, result.triangles)
    assert closed_out == closed_in and chi_out == chi_in, (chi_in, chi_out, closed_out)
    if mode == "fast":
        inputs = {tuple(v) for v in source.vertices}
        assert all(tuple(v) in inputs for v in result.vertices), "fast mode moved a vertex"
    digest = hashlib.sha256(out.read_bytes()).hexdigest()
    print(f"{mode}: {len(source.vertices)} -> {len(result.vertices)} vertices, chi {chi_out}, sha256 {digest}")


def main() -> int:
    args = sys.argv[1:]
    native = "--native" in args
    args = [a for a in args if a != "--native"]
    mesh = pathlib.Path(args[0]) if args else MESH
    try:
        with tempfile.TemporaryDirectory() as work:
            env = use_extension_layout(pathlib.Path(work)) if native else check_import()
            for mode in ("fast", "quality"):
                check_decimation(mesh, mode, pathlib.Path(work), env)
    except AssertionError as error:
        print(f"wheel check FAILED: {error}", file=sys.stderr)
        return 1
    print("wheel check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
