"""Error-bounded search benchmark: targets decimated, probes and time of ``max_error`` searches
next to one count-target decimation at the answer's count (a fresh mesh each, so both pay the
preparation), in both modes.

    /usr/bin/python3 tests/bench/bench_error_search.py [quality|fast ...]
"""

from __future__ import annotations

import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "build" / "python"), str(ROOT / "tests")]

import topstoc  # noqa: E402
from reference import read_off  # noqa: E402

BUNNY = ROOT.parent / "shared" / "meshes" / "genus0" / "cgal_bunny00.off"
DATA = ROOT / "tests" / "data"
#: (mesh, relative bound)
CASES = [(BUNNY, 0.003), (BUNNY, 0.01), (DATA / "genus_positive/cgal_elephant.off", 0.01),
         (DATA / "genus0/cgal_fandisk.off", 0.003), (DATA / "genus_positive/cgal_eight.off", 0.01)]


def run(path: pathlib.Path, bound: float, mode: str) -> dict:
    """One search and one count-target decimation at its answer, each on a fresh mesh."""
    vertices, triangles = read_off(path)
    started = time.perf_counter()
    report = topstoc.Mesh(vertices, triangles).decimate(max_error=bound, relative=True, seed=1,
                                                        mode=mode).error_bound
    search = time.perf_counter() - started
    started = time.perf_counter()
    topstoc.Mesh(vertices, triangles).decimate(target_vertices=report.target_vertices, seed=1, mode=mode)
    count = time.perf_counter() - started
    return dict(mesh=path.name, bound=bound, mode=mode, probes=len(report.probes),
                decimated=len({target for target, *_ in report.probes}), target=report.target_vertices,
                failed=report.failed_target, search=search, count=count)


def main() -> None:
    for path, bound in CASES:
        if not path.exists():
            print(f"{path.name}: missing, skipped")
            continue
        for mode in sys.argv[1:] or ["quality", "fast"]:
            r = run(path, bound, mode)
            print(f"{r['mesh']:22s} {bound:6.1%} {mode:8s} decimated {r['decimated']:3d} probes {r['probes']:3d} "
                  f"target {r['target']:6d} failed {r['failed']:6d} search {r['search']:6.2f} s "
                  f"count {r['count']:5.2f} s ratio {r['search'] / r['count']:6.1f}", flush=True)


if __name__ == "__main__":
    main()
