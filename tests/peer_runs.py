"""Running the peer programs (build/peers) and MeshLab for Hausdorff comparisons.

Shared by tests/python/test_hausdorff_peers.py and tests/bench/bench_hausdorff.py. Every helper
returns None (or the caller skips) when its peer is not available.
"""

from __future__ import annotations

import json
import os
import pathlib
import subprocess

import numpy as np

from reference import read_off  # noqa: F401  (re-exported for the benchmarks)

ROOT = pathlib.Path(__file__).resolve().parents[1]
PEERS = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "peers"


def write_off(path, vertices, triangles) -> None:
    with open(path, "w") as handle:
        handle.write(f"OFF\n{len(vertices)} {len(triangles)} 0\n")
        np.savetxt(handle, np.asarray(vertices, dtype=float), fmt="%.17g")
        np.savetxt(handle, np.column_stack([np.full(len(triangles), 3), triangles]), fmt="%d")


def peer(name: str):
    """Path of a peer program, or None when it was not built."""
    path = PEERS / name
    return path if path.is_file() and os.access(path, os.X_OK) else None


def cgal_hausdorff(a, b, error_bound_fraction=1e-4, mean_samples=1_000_000, seed=1, bounded=True):
    """CGAL's figures for files a, b (see tests/peers/cgal_hausdorff.cpp), or None."""
    program = peer("cgal_hausdorff")
    if program is None:
        return None
    args = [str(program), str(a), str(b), repr(error_bound_fraction), str(mean_samples), str(seed)]
    if not bounded:
        args.append("skip-bounded")
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def meshopt_simplify(source, output, target_index_count, sloppy=False):
    """meshoptimizer's simplification of file `source` written to `output`, or None."""
    program = peer("meshopt_simplify")
    if program is None:
        return None
    args = [str(program), str(source), str(output), str(int(target_index_count))] + (["sloppy"] if sloppy else [])
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def meshlab_hausdorff(a, b, samples=1_000_000):
    """MeshLab's Hausdorff filter (pymeshlab), both directions: {forward, backward} or None."""
    try:
        import pymeshlab
    except ImportError:
        return None
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(a))
    ms.load_new_mesh(str(b))
    out = {}
    for name, sampled, target in (("forward", 0, 1), ("backward", 1, 0)):
        r = ms.get_hausdorff_distance(sampledmesh=sampled, targetmesh=target, samplevert=True, sampleedge=True,
                                      sampleface=True, samplenum=int(samples),
                                      maxdist=pymeshlab.PercentageValue(100))
        out[name] = {"max": r["max"], "mean": r["mean"], "rms": r["RMS"], "samples": r["n_samples"]}
    return out
