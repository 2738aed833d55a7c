#!/usr/bin/python3
"""Scale: prepare + decimate time and peak memory per input triangle on generated meshes of
millions of triangles, next to meshopt_simplify in the same run (issue 39).

    /usr/bin/python3 tests/bench/bench_scale.py                      # 2M triangles
    /usr/bin/python3 tests/bench/bench_scale.py 2e6 20e6 100e6 --json docs/bench_results/bench_scale.json

The mesh is tests/meshgen.py's bumpy torus (closed, genus 1, a tenth of an edge of noise), at
1 % of its vertices, seed 1. Ours: each mode in a fresh process (tests/memory_peak.py): the time
of Mesh() (prepare) and of decimate(), and the peak resident memory above the interpreter's
baseline per input triangle, the input arrays included (float64 vertices, int32 triangles).
The peer: build/peers/meshopt_bench on the same mesh written as a binary PLY (float32 vertices),
meshopt_simplify and meshopt_simplifySloppy once each at the same fraction of the index count;
its memory is /usr/bin/time's maximum resident size of the whole program (reading included),
per triangle. "Cold" is prepare + decimate, which is what a fresh mesh costs.
"""

from __future__ import annotations

import argparse
import datetime
import json
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tests"), str(pathlib.Path(__file__).resolve().parent)]

import memory_peak  # noqa: E402
from machine import machine  # noqa: E402

PEER = ROOT / "build" / "peers" / "meshopt_bench"
MESHES = ROOT / "build" / "bench_meshes"

WRITE_PLY = r"""
import sys
sys.path.insert(0, {tests!r})
import numpy as np
import meshgen
vertices, triangles = meshgen.bumpy_torus({triangles})
face = np.dtype([("n", "u1"), ("v", "<i4", (3,))])
with open({path!r} + ".tmp", "wb") as out:
    out.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
               "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
               % (len(vertices), len(triangles))).encode())
    step = 1 << 22
    for start in range(0, len(vertices), step):
        out.write(vertices[start:start + step].astype("<f4").tobytes())
    for start in range(0, len(triangles), step):
        rows = np.empty(len(triangles[start:start + step]), face)
        rows["n"], rows["v"] = 3, triangles[start:start + step]
        out.write(rows.tobytes())
"""


def peer(triangles: int, ratio: float):
    """meshopt_bench on the same torus (written once under build/bench_meshes), or None."""
    if not PEER.exists() or shutil.which("time") != "/usr/bin/time":
        return None
    MESHES.mkdir(parents=True, exist_ok=True)
    path = MESHES / f"bumpy_torus_{triangles}.ply"
    if not path.exists():
        subprocess.run([sys.executable, "-c", WRITE_PLY.format(tests=str(ROOT / "tests"), triangles=triangles,
                                                               path=str(path))], check=True)
        pathlib.Path(str(path) + ".tmp").replace(path)
    done = subprocess.run(["/usr/bin/time", "-f", "%M", str(PEER), str(path), str(ratio), "1"],
                          capture_output=True, text=True)
    if done.returncode != 0:
        print(f"meshopt_bench failed: {done.stderr[-500:]}")
        return None
    figures = json.loads(done.stdout)
    return {"simplify_s": figures["simplify"]["median_seconds"],
            "sloppy_s": figures["simplify_sloppy"]["median_seconds"],
            "simplify_triangles": figures["simplify"]["triangles"],
            "bytes_per_triangle": int(done.stderr.split()[-1]) * 1024 / figures["triangles"]}


def save(path: pathlib.Path, rows: list, ratio: float) -> None:
    figures = {"benchmark": "tests/bench/bench_scale.py", "machine": machine(),
               "date": datetime.date.today().isoformat(), "ratio": ratio,
               "method": "bumpy torus from tests/meshgen.py, 1 % of the vertices, seed 1; each mode in a fresh "
                         "process: peak RSS above the interpreter's baseline per input triangle (input arrays "
                         "included), also the preparation's peak and the prepared mesh's resident size; "
                         "meshopt_bench once per size, /usr/bin/time's peak of the whole program",
               "sizes": rows}
    temporary = path.with_suffix(".json.tmp")
    temporary.write_text(json.dumps(figures, indent=1) + "\n")
    temporary.replace(path)  # atomic: never a half-written file under the final name


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("triangles", nargs="*", type=float, default=[2e6], help="mesh sizes (default 2e6)")
    parser.add_argument("--ratio", type=float, default=0.01)
    parser.add_argument("--no-peer", action="store_true", help="skip meshopt_bench")
    parser.add_argument("--json", metavar="FILE", help="write the figures and the machine here")
    args = parser.parse_args()
    if not memory_peak.available():
        print("skipped: /proc/self/clear_refs is not writable (Linux only)")
        return 0
    print(f"machine: {machine()}")
    rows = []
    for size in args.triangles:
        row = {}
        for mode in ("quality", "fast"):
            f = row[mode] = memory_peak.measure(int(size), mode, args.ratio)
            print(f"{f['triangles']:>11,} triangles, {mode:7}: prepare {f['prepare_s']:.2f} s, decimate "
                  f"{f['decimate_s']:.2f} s (cold {f['prepare_s'] + f['decimate_s']:.2f} s), peak "
                  f"{f['bytes_per_triangle']:.1f} B/triangle (preparation's {f['prepare_bytes_per_triangle']:.1f}, "
                  f"prepared mesh {f['prepared_bytes_per_triangle']:.1f})", flush=True)
        row["triangles"], row["vertices"] = row["quality"]["triangles"], row["quality"]["vertices"]
        row["meshopt"] = m = None if args.no_peer else peer(int(size), args.ratio)
        rows.append(row)
        if m:
            ratios = ", ".join(f"{mode} {m['simplify_s'] / (row[mode]['prepare_s'] + row[mode]['decimate_s']):.1f}x"
                               for mode in ("quality", "fast"))
            print(f"{'':>11}  meshopt_simplify {m['simplify_s']:.2f} s ({ratios} our cold time), simplifySloppy "
                  f"{m['sloppy_s']:.2f} s, peak {m['bytes_per_triangle']:.0f} B/triangle (whole program, reading "
                  "included)", flush=True)
        if args.json:  # after every size: a run stopped at a bigger size keeps the smaller ones
            save(pathlib.Path(args.json), rows, args.ratio)
    if len(rows) > 1:
        first, last = rows[0], rows[-1]
        for mode in ("quality", "fast"):
            t0 = first[mode]["prepare_s"] + first[mode]["decimate_s"]
            t1 = last[mode]["prepare_s"] + last[mode]["decimate_s"]
            print(f"{mode}: {last['triangles'] / first['triangles']:.1f}x the triangles took {t1 / t0:.1f}x the time")
    return 0


if __name__ == "__main__":
    sys.exit(main())
