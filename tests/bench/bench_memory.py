#!/usr/bin/python3
"""Peak resident memory of the engine's big jobs, each in a fresh process (issue 19 item 5).

    /usr/bin/python3 tests/bench/bench_memory.py

Jobs (meshes from ../shared; skips cleanly when absent):
  - prepare + decimate at 10 % on the 1.55M-triangle horse (the goal is 600 MB or less);
  - handle and tunnel loops on the genus-133 grid Loop-subdivided to 954,368 triangles
    (made by bench_loops.py, which this runs first when the mesh is missing).
The baseline is the same process after reading the file: the peak minus it is what the engine
adds. The peer is meshopt_simplify (build/peers/meshopt_bench) on the horse: /usr/bin/time's
maximum resident size of its whole run, file reading included.
"""

import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
HORSE = ROOT.parent / "shared" / "meshes" / "big" / "horse_loop2_1.55M.ply"
GRID = ROOT / "build" / "bench_meshes" / "grid133_l3.ply"
PEER = ROOT / "build" / "peers" / "meshopt_bench"

JOB = """
import resource, sys, time
sys.path.insert(0, {python!r})
from topstoc.core import Mesh, handle_tunnel_loops, read_mesh
data = read_mesh({path!r})
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
{work}
seconds = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(f"{{peak / 1024:.0f}} {{(peak - base) / 1024:.0f}} {{seconds:.2f}}")
"""


def run(name: str, path: pathlib.Path, work: str) -> None:
    code = JOB.format(python=str(ROOT / "build" / "python"), path=str(path), work=work)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    print(f"{name}: peak {out[0]} MB, of which {out[1]} MB above the read mesh; {out[2]} s")


def main() -> int:
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from machine import machine

    if not HORSE.exists():
        print(f"skipped: {HORSE} not found (the benchmark meshes live in ../shared/meshes)")
        return 0
    print(f"machine: {machine()}")
    run(f"prepare + decimate 10 %, {HORSE.name}", HORSE,
        "Mesh(data.vertices, data.triangles).decimate(ratio=0.1, seed=1)")
    if PEER.exists() and shutil.which("time") == "/usr/bin/time":
        time_out = subprocess.run(["/usr/bin/time", "-f", "%M", str(PEER), str(HORSE), "0.1", "1"],
                                  capture_output=True, text=True)
        if time_out.returncode == 0:
            print(f"peer meshopt_bench (read + simplify + sloppy): peak {int(time_out.stderr.split()[-1]) // 1024} MB")
    if not GRID.exists():
        subprocess.run([sys.executable, str(ROOT / "tests" / "bench" / "bench_loops.py"), "--only", "grid133_l3",
                        "--repeats", "1"], check=True, capture_output=True)
    run(f"handle and tunnel loops, {GRID.name} (genus 133)", GRID, "handle_tunnel_loops(Mesh(data.vertices, data.triangles))")
    return 0


if __name__ == "__main__":
    sys.exit(main())
