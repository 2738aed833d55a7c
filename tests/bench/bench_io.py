"""Mesh file reading and writing: topstoc.core.api.io against OpenMesh's readers, same run.

    /usr/bin/python3 tests/bench/bench_io.py [RUNS]

OpenMesh is timed by build/peers/plain_openmesh_read (its IOManager with a raw-array
BaseImporter, in C++), next to topstoc's native reader in the same process; this script adds
topstoc.core.api.io.read_mesh as Python users call it (file read included) and the writers.
Needs ../shared/meshes (skips otherwise) and a build (cmake --build build).
"""

import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build"))
SHARED = ROOT.parent / "shared" / "meshes"
MESHES = ["big/horse_loop2_1.55M.ply", "genus0/petsc_horse.ply.bz2", "big/dragon_vrip.ply.gz"]

sys.path.insert(0, str(BUILD / "python"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from machine import machine  # noqa: E402


def median_seconds(function, runs: int) -> float:
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> int:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    if not SHARED.is_dir():
        print(f"skipped: {SHARED} is not available")
        return 0
    try:
        from topstoc.core.api.io import read_mesh, write_mesh
    except ImportError as error:
        print(f"skipped: no build ({error})")
        return 0
    peer = BUILD / "peers" / "plain_openmesh_read"
    print(f"machine: {machine()}; median of {runs} runs")
    for name in MESHES:
        path = SHARED / name
        if not path.exists():
            print(f"{name}: skipped (missing)")
            continue
        data = read_mesh(path)
        ours = median_seconds(lambda: read_mesh(path), runs)
        print(f"{name}: {data.num_vertices} vertices, {data.num_triangles} triangles")
        print(f"  topstoc read_mesh (Python, file read + decompression included): {ours:.3f} s")
        if peer.exists() and not name.endswith((".gz", ".bz2")):
            done = subprocess.run([str(peer), str(path), str(runs)], capture_output=True, text=True)
            if done.returncode == 0:
                report = json.loads(done.stdout)
                om, native = report["openmesh"]["median_seconds"], report["topstoc"]["median_seconds"]
                print(f"  OpenMesh 9.0 IOManager::read (C++, raw importer): {om:.3f} s"
                      f"{' (float32 positions)' if report['openmesh']['float_positions'] else ''}")
                print(f"  topstoc read_mesh_path (C++): {native:.3f} s; OpenMesh / topstoc = {om / native:.2f}")
            else:
                print(f"  peer failed: {done.stderr.strip()}")
        elif not peer.exists():
            print("  OpenMesh peer not built (build/peers/plain_openmesh_read)")
        with tempfile.TemporaryDirectory() as folder:
            for suffix in (".ply", ".obj", ".off", ".stl", ".ply.gz"):
                target = pathlib.Path(folder) / f"out{suffix}"
                write = median_seconds(lambda: write_mesh(target, data), 1 if suffix.endswith(".gz") else runs)
                read = median_seconds(lambda: read_mesh(target), runs)
                print(f"  {suffix:7s} write {write:.3f} s, read back {read:.3f} s, {target.stat().st_size / 1e6:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
