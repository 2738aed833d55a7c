#!/usr/bin/python3
"""Slow corners: prepare + decimate time and peak memory per input triangle on every family of
tests/shape_families.py at one size, next to the bumpy torus of that size (issue 39: performance
that holds off the benchmark's own mesh).

    /usr/bin/python3 tests/bench/bench_families.py [--triangles 1e6] [--ratios 0.01 0.1]
        [--baseline OTHER_BUILD] [--json docs/bench_results/bench_families.json]

Each family, mode and ratio runs in a fresh process (tests/memory_peak.py): the time of
Mesh() and of decimate(), and the peak resident memory above the interpreter's baseline per input
triangle, the input arrays included. "÷ torus" is a family's cold time over the bumpy torus's at
the same mode and ratio: the cost of the shape itself. With --baseline, another build (main's)
runs each case right after this one, and the table gives its time and peak too.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tests"), str(pathlib.Path(__file__).resolve().parent)]

import memory_peak  # noqa: E402
from machine import machine, save_figures  # noqa: E402
from shape_families import FAMILIES  # noqa: E402


def cold(figures: dict) -> float:
    return figures["prepare_s"] + figures["decimate_s"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--triangles", type=float, default=1e6)
    parser.add_argument("--ratios", type=float, nargs="+", default=[0.01, 0.1])
    parser.add_argument("--modes", nargs="+", default=["quality", "fast"])
    parser.add_argument("--families", nargs="+", default=list(FAMILIES), choices=list(FAMILIES))
    parser.add_argument("--baseline", type=pathlib.Path, help="another build to run each case after this one")
    parser.add_argument("--note", default="", help="a line on what was compared")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    build = pathlib.Path(os.environ.get("TOPSTOC_BUILD", ROOT / "build")).resolve()
    print(machine())
    rows = []
    for family in args.families:
        for mode in args.modes:
            for ratio in args.ratios:
                row = {"family": family, "mode": mode, "ratio": ratio,
                       "ours": memory_peak.measure(args.triangles, mode, ratio, family, build)}
                if args.baseline:
                    row["baseline"] = memory_peak.measure(args.triangles, mode, ratio, family, args.baseline.resolve())
                reference = next((r for r in rows if r["family"] == "bumpy_torus" and r["mode"] == mode
                                  and r["ratio"] == ratio), row)
                ours = row["ours"]
                line = (f"{family:18s} {mode:7s} {ratio:5.2f}: {ours['triangles']:>9,} triangles, prepare "
                        f"{ours['prepare_s']:.2f} s + decimate {ours['decimate_s']:.2f} s "
                        f"({cold(ours) / cold(reference['ours']):.1f}x the torus), "
                        f"peak {ours['bytes_per_triangle']:.0f} B/triangle")
                if args.baseline:
                    base = row["baseline"]
                    line += f"; baseline {cold(base):.2f} s, {base['bytes_per_triangle']:.0f} B/triangle"
                print(line, flush=True)
                rows.append(row)
    if args.json:
        method = ("tests/shape_families.py at --triangles, seed 1; each family, mode and ratio in a fresh process: "
                  "prepare + decimate seconds and peak RSS above the interpreter's baseline per input triangle "
                  "(input arrays included)" + ("; the baseline build right after each case" if args.baseline else ""))
        save_figures(args.json, "tests/bench/bench_families.py", method, note=args.note, rows=rows,
                     baseline=str(args.baseline) if args.baseline else None)
    return 0


if __name__ == "__main__":
    sys.exit(main())
