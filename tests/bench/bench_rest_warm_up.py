"""CPU seconds of the Live Preview's rested Quality computation, cold and after a warm-up
(core.api.decimate.warm_up, blender/preview/warm_up.py), outside Blender so that other programs'
load inflates them less than the wall times of bench_blender_decimate.py --only-rest.

    TOPSTOC_NUM_THREADS=1 python3 tests/bench/bench_rest_warm_up.py [--mesh PATH|bumpy_torus:N ...]
        [--ratios 0.1 0.01] [--repeat 3] [--cold-only]

Per mesh and ratio, medians of the repeats: *cold*, a decimation with nothing kept; *warm-up*, the
warm-up toward HEADROOM times the ratio (what the preview does when the drag starts); *rest*, the
decimation at the ratio after it, checked to be the cold result array for array. ``--cold-only``
measures only the cold decimation, which a build without warm-ups can run too (TOPSTOC_BUILD).
"""

import argparse
import os
import pathlib
import statistics
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")) / "python"), str(ROOT / "tests")]
import meshgen  # noqa: E402
from machine import machine  # noqa: E402
from topstoc.core import Mesh  # noqa: E402
from topstoc.core.api.decimate import run_job  # noqa: E402
from topstoc.core.api.job import make_job  # noqa: E402

HEADROOM = 1.15  # blender/preview/warm_up.py's
MESHES = [str(ROOT.parent / "shared" / "meshes" / "genus0" / name) for name in ("cgal_bunny00.off", "cgal_armadillo.off")]
MESHES += ["bumpy_torus:100000", "bumpy_torus:150000", str(ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply")]
FIELDS = ("vertices", "triangles", "kept", "face_source", "corner_source", "samples")


def read(spec):
    if spec.startswith("bumpy_torus:"):
        return meshgen.bumpy_torus(int(spec.split(":", 1)[1]))
    from topstoc.core.api.io import read_mesh

    data = read_mesh(spec)
    return data.vertices, data.triangles


def cpu(call):
    start = time.process_time()
    result = call()
    return result, time.process_time() - start


def measure(mesh, ratio, cold_only):
    """(cold, warm-up, rest) CPU seconds of one round; warm-up and rest None with cold_only."""
    mesh.clear_floods()
    cold, seconds = cpu(lambda: run_job(mesh, make_job(mesh, ratio=ratio)))
    if cold_only:
        return seconds, None, None
    from topstoc.core.api.decimate import warm_up

    mesh.clear_floods()
    _, warming = cpu(lambda: warm_up(mesh, make_job(mesh, ratio=min(1.0, HEADROOM * ratio))))
    rest, resting = cpu(lambda: run_job(mesh, make_job(mesh, ratio=ratio)))
    for name in FIELDS:
        if not np.array_equal(getattr(rest, name), getattr(cold, name)):
            raise SystemExit(f"error: the rest after a warm-up differs from the cold result in {name}")
    return seconds, warming, resting


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", nargs="+", default=MESHES)
    parser.add_argument("--ratios", type=float, nargs="+", default=[0.1, 0.01])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--cold-only", action="store_true")
    args = parser.parse_args(argv)
    print(f"machine: {machine()}")
    for spec in args.mesh:
        if not spec.startswith("bumpy_torus:") and not os.path.exists(spec):
            print(f"skipped: {spec} is not available")
            continue
        mesh = Mesh(*read(spec))
        for ratio in args.ratios:
            rounds = [measure(mesh, ratio, args.cold_only) for _ in range(args.repeat)]
            cold = statistics.median(r[0] for r in rounds)
            line = f"{pathlib.Path(spec).name} ({mesh.num_triangles:,} triangles) at {ratio}: cold {cold:.3f} s"
            if not args.cold_only:
                warming, resting = (statistics.median(r[i] for r in rounds) for i in (1, 2))
                line += f", warm-up {warming:.3f} s, rest after it {resting:.3f} s ({resting / cold:.2f} of cold)"
            print(line + f" CPU, medians of {args.repeat}; load {os.getloadavg()[0]:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
