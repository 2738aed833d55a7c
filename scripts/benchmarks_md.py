#!/usr/bin/python3
"""Makes docs/benchmarks.md from the benchmarks' saved figures and the hand-written notes.

    python3 scripts/benchmarks_md.py           # rewrite docs/benchmarks.md
    python3 scripts/benchmarks_md.py --check   # exit 1 when docs/benchmarks.md is not its output

Inputs: docs/bench_results/*.json (written by `tests/bench/bench_*.py --json FILE`, or figures
carried over from before the benchmarks wrote JSON, marked "carried_over") in name order, then
docs/bench_notes/*.md (history, goals, explanations) in name order, appended as they are.
tests/python/test_benchmarks_md.py checks that the committed file is this script's output.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import statistics
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "bench"))
from quality_goals import EXACT, PEERS, error_ratio, goal_ratios  # noqa: E402
RESULTS = ROOT / "docs" / "bench_results"
NOTES = ROOT / "docs" / "bench_notes"
OUTPUT = ROOT / "docs" / "benchmarks.md"

HEADER = """# Benchmarks

Speed and quality next to the peers, each peer measured in the same run (the ratios travel
between machines better than the times). Made by `scripts/benchmarks_md.py` from the figures the
benchmarks saved (`docs/bench_results/*.json`, written by `tests/bench/bench_*.py --json FILE`)
and the notes in `docs/bench_notes/`; edit those, then run the script (a test checks this file
is its output). Speed is never asserted in tests; it lives here.
"""


def ms(value: float) -> str:
    """A time in milliseconds, rounded as the benchmarks print it."""
    return f"{value / 1000:.2f} s" if value >= 1000 else f"{value:.0f} ms"


def times(peer_ms, ours_ms) -> str:
    """How many times faster ours is; a dash when the peer did not run."""
    return "—" if peer_ms is None else f"{peer_ms / ours_ms:.1f}×"


def source_lines(figures: dict) -> list[str]:
    """Machine, method and date, stated once per result file."""
    lines = [f"- Machine: {figures['machine']}", f"- Date: {figures['date']}"]
    if figures.get("method"):
        lines.append(f"- Method: {figures['method']}")
    if figures.get("note") and not figures.get("carried_over"):
        lines.append(f"- Note: {figures['note']}")
    return lines


def render_decimate(name: str, figures: dict) -> str:
    """bench_decimate.py --json: the horse (or another mesh) in both modes next to meshoptimizer."""
    mesh = figures["mesh"]
    first = figures["ratios"][0]
    out = [f"## Decimation speed (`{name}`)", "",
           f"`{figures['benchmark']}` on {mesh['name']} ({mesh['vertices']:,} vertices, "
           f"{mesh['triangles']:,} triangles): medians of {figures['repeats']} seeds per target, "
           "the peer (`build/peers/meshopt_bench`, same file, same vertex fraction) in the same run.", "",
           *source_lines(figures), "",
           f"Prepare (validation, adjacency, weights): {ms(figures['prepare_ms'])}; first decimation "
           f"at {first['ratio']:.0%} (prepare + fast decimate): {ms(figures['first_ms'])}, "
           f"{times(first['meshopt_simplify_ms'], figures['first_ms'])} meshopt_simplify; "
           f"quality mode cold (prepare + decimate at {first['ratio']:.0%}): {ms(figures['cold_quality_ms'])}.", "",
           "| Target | Fast mode | Slider step | Live-preview frame / step | Quality mode (default) "
           "| meshopt_simplify | meshopt_simplifySloppy | simplify ÷ fast | simplify ÷ quality |",
           "|---|---|---|---|---|---|---|---|---|"]
    for row in figures["ratios"]:
        simplify, sloppy = row["meshopt_simplify_ms"], row["meshopt_sloppy_ms"]
        out.append(
            f"| {row['ratio']:.0%} ({row['vertices']:,} vertices) | {ms(row['fast_ms'])} "
            f"| {ms(row['slider_step_ms'])} ({row['slider_steps_updated']} of {row['slider_steps']} updated) "
            f"| {ms(row['draft_ms'])} / {ms(row['draft_step_ms'])} | {ms(row['quality_ms'])} "
            f"| {'—' if simplify is None else ms(simplify)} | {'—' if sloppy is None else ms(sloppy)} "
            f"| {times(simplify, row['fast_ms'])} | {times(simplify, row['quality_ms'])} |")
    out += ["", "Fast-mode stages at each target (medians): " + "; ".join(
        f"{row['ratio']:.0%}: " + ", ".join(f"{stage} {value:.0f}" for stage, value in row["stages_ms"].items()
                                             if value > 0) + " ms" for row in figures["ratios"]) + "."]
    return "\n".join(out) + "\n"


QUALITY_FIGURES = (("mean", "mean error"), ("max", "max error"), ("ar_mean", "aspect ratio mean"),
                   ("ar_max", "worst triangle"))


def percent(ratio: float) -> str:
    return f"{ratio:.0%}" if round(ratio * 100, 6).is_integer() else f"{ratio:.1%}"


def goal_lines(cases: list) -> list:
    """The goals' medians and worst cases, then one row per case."""
    out = ["", "Only the peers that reached our count (at most 5 % and two triangles above it) enter these "
           "figures: a peer stopped far above it measures a larger mesh.", ""]
    goals = (("mean ÷ the better of Blender and MeshLab", 0.9, 1.0), ("max ÷ the best peer", 1.0, 1.15))
    # runs before mode "best" have no such tool: only the quality mode's lines
    modes = [m for m in ("quality", "best") if any(c["tools"].get(f"topstoc {m}") for c in cases)]
    for mode, kept, index in ((m, k, i) for m in modes for k in (False, True) for i in range(2)):
        what, median_goal, every_goal = goals[index]
        what += " that kept the topology" if kept else ""
        what = f"{what} ({mode} mode)" if len(modes) > 1 else what
        ranked = [(ratio, c) for c in cases if (ratio := goal_ratios(c, mode, kept)[index]) is not None]
        if not ranked:
            continue
        worst, case = max(ranked, key=lambda pair: pair[0])
        values = [v for v, _ in ranked]
        target = percent(case["ratio"]) if case.get("ratio") is not None else f"{case['budget']} triangles"
        out.append(f"- {what}: median {statistics.median(values):.3f} (goal ≤ {median_goal}), worst "
                   f"{worst:.2f} ({case['mesh']} at {target}), above {every_goal} in "
                   f"{sum(v > every_goal for v in values)}/{len(values)} cases (goal: none); no such peer "
                   f"reached our count in {len(cases) - len(values)}.")
    out += ["", "The second pair of columns takes only the peers whose result kept every component's topology, "
            "as ours does.", "",
            "| Mesh | Target | Triangles | Mean ÷ better of Blender, MeshLab | Max ÷ best peer | "
            "Mean, peers that kept the topology | Max, peers that kept the topology | Topology kept |",
            "|---|---|---|---|---|---|---|---|"]
    for case in cases:
        ours = case["tools"]["topstoc quality"]
        target = percent(case["ratio"]) if case.get("ratio") is not None else f"{case['budget']} triangles"
        cells = [f"{v:.2f}" if v is not None else "—" for v in (*goal_ratios(case), *goal_ratios(case, kept_topology=True))]
        over = f" ({ours['over_budget_reason']})" if ours.get("over_budget") else ""
        out.append(f"| {case['mesh']} | {target} | {ours['triangles']:,}{over} | {' | '.join(cells)} | "
                   f"{'yes' if ours['topology'] else 'NO'} |")
    return out


def render_quality(name: str, figures: dict) -> str:
    """bench_quality.py --json: the quality mode's error and shape over the peers' at its triangle count."""
    cases = figures["cases"]
    ours = [case["tools"]["topstoc quality"] for case in cases]
    ratios = sorted({case["ratio"] for case in cases if case.get("ratio") is not None}, reverse=True)
    budgets = sorted({case["budget"] for case in cases if case.get("ratio") is None}, reverse=True)
    targets = ", ".join([percent(ratio) for ratio in ratios] + [f"{budget} triangles" for budget in budgets])
    out = [f"## Result quality next to the quadric decimators (`{name}`)", "",
           f"`{figures['benchmark']}`: {len(cases)} cases ({len({c['mesh'] for c in cases})} meshes × "
           f"{targets}); every peer decimates to the triangle count "
           f"of our quality result; symmetric Hausdorff error with {figures['samples']:,} samples, aspect ratio as "
           "thesis eq. 4.2. Medians over the cases of ours ÷ the peer's figure (below 1: ours is better), the "
           "worst case in brackets.", "", *source_lines(figures), "",
           "| Peer | " + " | ".join(label for _, label in QUALITY_FIGURES) + " | topology kept (peer) |",
           "|---|" + "---|" * (len(QUALITY_FIGURES) + 1)]
    for peer in PEERS:
        pairs = [(case["tools"]["topstoc quality"], case["tools"][peer]) for case in cases if case["tools"].get(peer)]
        if not pairs:
            out.append(f"| {peer} | not available |" + " |" * len(QUALITY_FIGURES))
            continue
        cells = []
        for key, _ in QUALITY_FIGURES:
            ratios = [error_ratio(a[key], b[key]) for a, b in pairs]
            cells.append(f"{statistics.median(ratios):.3f}× [{max(ratios):.2f}]" if ratios else "—")
        kept = sum(bool(b["topology"]) for _, b in pairs)
        out.append(f"| {peer} | " + " | ".join(cells) + f" | {kept}/{len(pairs)} |")
    out += ["", f"TopStoc's quality mode kept the topology in {sum(bool(o['topology']) for o in ours)}/{len(ours)} "
            f"cases, with {sum(o['zero_area'] for o in ours)} zero-area triangles and a worst aspect ratio of "
            f"{max(o['ar_max'] for o in ours):.0f}."]
    out += goal_lines(cases)
    return "\n".join(out) + "\n"


def render_loop_families(name: str, figures: dict) -> str:
    """bench_loops.py --families --json: loops per generated family, next to the 7 x 19 grid and the baseline build."""
    rows = figures["families"]
    grid = rows[0]
    with_baseline = all("baseline" in row for row in rows)
    out = [f"## Handle and tunnel loops across shapes (`{name}`)", "",
           f"`{figures['benchmark']}`: each family of `tests/loop_families.py` at its size and genus, "
           f"next to the {grid['name']} reference (CPU seconds over the grid's: the cost should follow size and "
           "genus, not the shape). Issue 39's goal: ≤ 1 s for any genus ≤ 150 mesh of ≤ 20k triangles, "
           "≤ 10 s for genus 1,000 at 1M triangles.", "", *source_lines(figures), "",
           "| Family | Triangles | Genus (components) | Route | Wall | CPU | Selection (wall) | CPU ÷ grid |"
           + (" Before: wall / CPU / selection (wall) | CPU speed-up |" if with_baseline else ""),
           "|---|---|---|---|---|---|---|---|" + ("---|---|" if with_baseline else "")]
    for row in rows:
        line = (f"| {row['name']} | {row['triangles']:,} | {row['genus']} ({row['components']}) | "
                f"{'/'.join(row['routes'])} | {row['seconds']:.2f} s | {row['cpu']:.2f} s | "
                f"{row['stages']['select']:.2f} s | {row['cpu'] / grid['cpu']:.2f} |")
        if with_baseline:
            before = row["baseline"]
            line += (f" {before['seconds']:.2f} / {before['cpu']:.2f} / {before['stages']['select']:.2f} s | "
                     f"{before['cpu'] / row['cpu']:.1f}× |")
        out.append(line)
    return "\n".join(out) + "\n"


def render_scale(name: str, figures: dict) -> str:
    """bench_scale.py --json: prepare + decimate time and peak memory per triangle by mesh size."""
    out = [f"## Scale: time and memory by mesh size (`{name}`)", "",
           f"`{figures['benchmark']}` at {percent(figures['ratio'])} of the vertices; cold = prepare + decimate in a "
           "fresh process; peak = resident memory above the interpreter's baseline, per input triangle, input arrays "
           "included. meshopt_simplify in the same run (its peak: the whole program, file reading included).", "",
           *source_lines(figures), "",
           "| Triangles | Mode | Prepare | Decimate | Cold | Peak per triangle | meshopt_simplify "
           "| simplify ÷ cold | meshopt peak per triangle |", "|---|---|---|---|---|---|---|---|---|"]
    for row in figures["sizes"]:
        peer = row.get("meshopt")
        for mode in ("quality", "fast"):
            f = row[mode]
            cold = f["prepare_s"] + f["decimate_s"]
            out.append(f"| {row['triangles']:,} | {mode} | {ms(1000 * f['prepare_s'])} | {ms(1000 * f['decimate_s'])} "
                       f"| {ms(1000 * cold)} | {f['bytes_per_triangle']:.0f} B "
                       f"| {'—' if peer is None else ms(1000 * peer['simplify_s'])} "
                       f"| {times(None if peer is None else peer['simplify_s'], cold)} "
                       f"| {'—' if peer is None else format(peer['bytes_per_triangle'], '.0f') + ' B'} |")
    sizes = figures["sizes"]
    if len(sizes) > 1:
        growth = [f"{mode} {(sizes[-1][mode]['prepare_s'] + sizes[-1][mode]['decimate_s']) / (sizes[0][mode]['prepare_s'] + sizes[0][mode]['decimate_s']):.1f}×"
                  for mode in ("quality", "fast")]
        out += ["", f"From {sizes[0]['triangles']:,} to {sizes[-1]['triangles']:,} triangles "
                f"({sizes[-1]['triangles'] / sizes[0]['triangles']:.0f}× the size) the cold time grew "
                + " and ".join(growth) + "."]
    return "\n".join(out) + "\n"


def render_families(name: str, figures: dict) -> str:
    """bench_families.py --json: time and peak memory per shape family at one size, next to the torus."""
    baseline = figures.get("baseline")
    out = [f"## Slow corners: shape families at one size (`{name}`)", "",
           f"`{figures['benchmark']}`: cold = prepare + decimate in a fresh process; peak = resident memory above the "
           "interpreter's baseline, per input triangle, input arrays included; ÷ torus = the family's cold time over "
           "the bumpy torus's at the same mode and ratio." + (" The baseline build ran each case right after."
                                                               if baseline else ""), "", *source_lines(figures), "",
           "| Family | Triangles | Mode | Ratio | Cold | ÷ torus | Peak per triangle | Target missed |"
           + (" Baseline cold | Baseline peak |" if baseline else ""),
           "|---|---|---|---|---|---|---|---|" + ("---|---|" if baseline else "")]
    torus = {(r["mode"], r["ratio"]): r["ours"] for r in figures["rows"] if r["family"] == "bumpy_torus"}
    for row in figures["rows"]:
        f, ref = row["ours"], torus.get((row["mode"], row["ratio"]))
        cold = f["prepare_s"] + f["decimate_s"]
        cells = (f"| {row['family'].replace('_', ' ')} | {f['triangles']:,} | {row['mode']} | {percent(row['ratio'])} "
                 f"| {ms(1000 * cold)} | {'—' if ref is None else format(cold / (ref['prepare_s'] + ref['decimate_s']), '.1f') + '×'} "
                 f"| {f['bytes_per_triangle']:.0f} B | {'yes' if f['target_missed'] else 'no'} |")
        if baseline:
            b = row["baseline"]
            cells += f" {ms(1000 * (b['prepare_s'] + b['decimate_s']))} | {b['bytes_per_triangle']:.0f} B |"
        out.append(cells)
    return "\n".join(out) + "\n"


def render_high_valence(name: str, figures: dict) -> str:
    """bench_high_valence.py --json: decimation time on fans of slivers, this build and a baseline."""
    modes = figures["modes"]
    out = [f"## Vertices of high valence: fans of slivers (`{name}`)", "",
           f"`{figures['benchmark']}` at {percent(figures['ratio'])} of the vertices, one thread; the baseline is "
           "another build (main's) in the same run.", "", *source_lines(figures), "",
           "| Mesh | Size | Triangles | Mode | Ours | Baseline | Baseline ÷ ours | Error mean, max: ours | Baseline's |",
           "|---|---|---|---|---|---|---|---|---|"]
    limit = f"over {figures['limit_s']:.0f} s"
    for row in figures["meshes"]:
        ours, base = row["ours"], row.get("baseline")
        for mode in modes:
            mine = ours[mode]["seconds"] if ours else None
            theirs = base[mode]["seconds"] if base else None
            out.append(f"| {row['shape']} | {row['size']:,} | {ours['triangles'] if ours else 2 * row['size']:,} | {mode} "
                       f"| {limit if mine is None else ms(1000 * mine)} | {limit if theirs is None else ms(1000 * theirs)} "
                       f"| {'—' if mine is None or theirs is None else times(theirs, mine)} "
                       f"| {fan_error(ours, mode)} | {fan_error(base, mode)} |")
    return "\n".join(out) + "\n"


def fan_error(run: dict | None, mode: str) -> str:
    """A bench_high_valence.py result's Hausdorff mean and max (% of the diagonal), where measured."""
    figures = run.get(mode, {}) if run else {}
    if "error_mean" not in figures:
        return "—"
    return f"{figures['error_mean']:.3g} %, {figures['error_max']:.3g} %"


def render_blender_memory(name: str, figures: dict) -> str:
    """bench_blender_background.py --memory --json: Guided Decimate's peak above Blender's mesh next to the engine's."""
    out = [f"## Guided Decimate's memory in Blender (`{name}`)", "",
           f"`{figures['benchmark']}`, Blender {figures['blender']}, Guided Decimate at {percent(figures['ratio'])} "
           "of the vertices; peak = resident memory above Blender's own mesh, per triangle.", "",
           *source_lines(figures), "",
           "| Triangles | Mode | Guided Decimate | Engine alone | Difference | Its time | The engine's |",
           "|---|---|---|---|---|---|---|"]
    for row in figures["runs"]:
        addon, engine = row["addon"], row["engine"]
        out.append(f"| {addon['triangles']:,} | {row['mode']} | {addon['bytes_per_triangle']:.0f} B "
                   f"| {engine['bytes_per_triangle']:.0f} B "
                   f"| {addon['bytes_per_triangle'] - engine['bytes_per_triangle']:.1f} B "
                   f"| {ms(1000 * addon['seconds'])} | {ms(1000 * engine['seconds'])} |")
    return "\n".join(out) + "\n"


def render_cleanup_speed(name: str, figures: dict) -> str:
    """bench_cleanup.py --speed --json: the clean-up's time on many small handles, before and after."""
    cases = figures["cases"]
    with_baseline = any("baseline" in row for row in cases)
    out = [f"## Clean-up speed: many small handles (`{name}`)", "",
           f"`{figures['benchmark']}`: a block with K unit arches (loops about 4) and 4 large ones (loops 12), "
           "jittered by 0.05 and subdivided L times, cleaned with size 6. Issue 43's goal: 1,000 handles on a "
           "1M-triangle mesh in ≤ 10 s.", "", *source_lines(figures), "",
           "| Arches, subdivisions | Triangles | Genus before → after | Loops left below the size | Worst patch aspect "
           "| Patches | Wall | CPU | Loops (wall) |" + (" Before: wall / CPU | CPU speed-up |" if with_baseline else ""),
           "|---|---|---|---|---|---|---|---|---|" + ("---|---|" if with_baseline else "")]
    for row in cases:
        styles = ", ".join(f"{count} {style}" for style, count in sorted(row["styles"].items()))
        line = (f"| {row['small_arches']:,}, {row['subdivisions']} | {row['triangles']:,} | {row['genus_before']} → "
                f"{row['genus_after']} | {row['loops_left_below']} | {row['patch_aspect']:.2f} | {styles} "
                f"| {row['wall']:.1f} s | {row['cpu']:.1f} s | {row['loops_wall']:.1f} s |")
        before = row.get("baseline")
        if with_baseline:
            line += (" — | — |" if before is None else
                     f" {before['wall']:.1f} s / {before['cpu']:.1f} s | {before['cpu'] / row['cpu']:.1f}× |")
        out.append(line)
    return "\n".join(out) + "\n"


def render_blender_rest(name: str, figures: dict) -> str:
    """bench_blender_decimate.py --only-rest --json: seconds from a drag resting to the Live Preview's
    Quality result, per mesh and ratio, for each build measured (before, after)."""
    labels = sorted({label for mesh in figures["meshes"] for row in mesh["ratios"].values() for label in row},
                    key=lambda label: (label != "before", label))
    out = [f"## Live Preview: drag rested → Quality result (`{name}`)", "",
           f"`{figures['benchmark']}` in Blender {figures['blender']}. Issue 39's goal: ≤ 0.3 s up to 200k "
           "triangles, ≤ 1 s on the horse. Per build: the rest's seconds (the Quality computation's own seconds; "
           "updates shown per second during the drag; load average).", "", *source_lines(figures), "",
           "| Mesh | Triangles | Ratio | " + " | ".join(labels) + " |", "|---|---|---|" + "---|" * len(labels)]
    for mesh in figures["meshes"]:
        for ratio, row in mesh["ratios"].items():
            cells = ["—" if row.get(label) is None else
                     f"{row[label]['rest_s']:.3f} s ({row[label]['computed_s']:.3f} s; "
                     f"{row[label]['drag_updates_per_s']:.0f}/s; load {row[label]['load_average']:.1f})"
                     for label in labels]
            out.append(f"| {mesh['mesh']} | {mesh['triangles']:,} | {percent(float(ratio))} | " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


def render_carried_over(name: str, figures: dict) -> str:
    """Figures measured before the benchmarks saved JSON, kept as they were published."""
    out = [f"## {figures['title']} (`{name}`)", "", *source_lines(figures), "", figures["note"], "",
           "| What | TopStoc | Peer, same run | Ratio |", "|---|---|---|---|"]
    out += [f"| {row['what']} | {row['topstoc']} | {row['peer']} | {row['ratio']} |" for row in figures["rows"]]
    return "\n".join(out) + "\n"


def render_paired(name: str, figures: dict) -> str:
    """bench_threads_paired.py --json: two builds in alternating runs, the median of the pair ratios."""
    pairs = figures["pairs"]
    out = [f"## Paired runs: {figures['new']} against {figures['old']} (`{name}`)", "",
           *source_lines(figures),
           f"- Method: `tests/bench/bench_decimate.py` on {figures['mesh']} at {figures['ratio']:.0%}, "
           f"{figures['repeats']} repeats per run, {len(pairs)} pairs of runs with the builds alternating; "
           f"load average {figures['load_average']:.1f} at the end", "",
           "| Figure | Old (median) | New (median) | New / old, median of the pairs | Pairs' range |",
           "|---|---|---|---|---|"]
    for label, ratio in figures["median_ratio"].items():
        ratios = [p[label]["new"] / p[label]["old"] for p in pairs]
        old = statistics.median(p[label]["old"] for p in pairs)
        new = statistics.median(p[label]["new"] for p in pairs)
        out.append(f"| {label} | {ms(old)} | {ms(new)} | {ratio:.3f} | {min(ratios):.3f}–{max(ratios):.3f} |")
    return "\n".join(out) + "\n"


def render_attributes(name: str, figures: dict) -> str:
    """bench_attributes.py --json: UV, normal and colour error next to meshoptimizer and Blender."""
    units = {"uv": "UV (texture units)", "normal": "normal (°)", "color": "colour (RGB)"}
    peers = ("meshopt_simplifyWithAttributes", "Blender Collapse")
    out = [f"## The look after decimation (`{name}`)", "", *source_lines(figures),
           f"- Method: `tests/bench/bench_attributes.py`, mean error over {figures['samples']} points per direction "
           f"(`tests/attribute_error.py`); ours at attribute weight {figures['attribute_weight']}, each peer at our "
           "triangle count; ours ÷ peer below 1 means ours is closer to the source's look", "",
           "| Asset | Target | Triangles (target: ours / meshopt / Blender) | Error | Ours | meshopt | Blender | "
           "Ours ÷ meshopt | Ours ÷ Blender |", "|---|---|---|---|---|---|---|---|---|"]
    units = {**units, "geometry_mean": "geometry, mean (% of diagonal)"}
    for case in figures["cases"]:
        tools = case["tools"]
        ours = tools["topstoc quality"]
        counts = " / ".join("—" if tools.get(t) is None else str(tools[t]["triangles"])
                            for t in ("topstoc quality", *peers))
        for channel in [*case["channels"], "geometry_mean"]:
            cells = ["—" if tools.get(p) is None else f"{tools[p][channel]:.4g}" for p in peers]
            ratios = ["—" if tools.get(p) is None else attribute_ratio(ours[channel], tools[p][channel], channel)
                      for p in peers]
            out.append(f"| {case['asset']} | {case['ratio']:.0%} | {case['target_triangles']}: {counts} | {units[channel]} | "
                       f"{ours[channel]:.4g} | {' | '.join(cells)} | {' | '.join(ratios)} |")
    out += ["", "| Ours ÷ peer | Median | Worst | Above 1.0 |", "|---|---|---|---|"]
    for label, entry in figures["summary"].items():
        out.append(f"| {label} | {entry['median']:.3f} | {entry['worst']:.3f} | {entry['above_1']} of {entry['cases']} |")
    return "\n".join(out) + "\n"


def attribute_ratio(ours: float, peer: float, channel: str) -> str:
    """ours / peer as bench_attributes.py computes it (both raised to the noise floor first)."""
    floor = EXACT if channel == "geometry_mean" else 1e-9
    value = max(ours, floor) / max(peer, floor)
    return f"{value:.2f}" if value < 100 else "> 100"


def _signed_percent(value) -> str:
    return "—" if value is None else f"{100 * value:+.2f} %"


def render_cleanup(name: str, figures: dict) -> str:
    """bench_cleanup.py --json: handles against a voxel remesh at the same detail, holes against
    PyMeshFix and MeshLab on the same plates."""
    out = [f"## Topology clean-up next to MeshLab and PyMeshFix (`{name}`)", "",
           f"`{figures['benchmark']}`: small handles removed below the size, the rest of the surface kept; "
           "the anchor for handles is a voxel remesh at the same detail (MeshLab's Uniform Mesh Resampling, "
           "marching cubes on cells one mean edge long), which removes handles by throwing the surface away: "
           "the genus it leaves and the area it changes. PyMeshFix's repair keeps every handle.", "",
           *source_lines(figures), "",
           "| Case | Triangles | Genus before → after (ours) | Voxel remesh: genus after | PyMeshFix repair: genus "
           "after | Area changed: ours / voxel | Voxel ÷ ours (area change) | Input triangles kept (ours) "
           "| Worst patch aspect | Time: ours (loops) / voxel |", "|---|---|---|---|---|---|---|---|---|---|"]
    for row in figures["handles"]:
        voxel = row.get("voxel")
        ratio = "—" if voxel is None else f"{abs(voxel['area_change']) / max(abs(row['area_change']), 1e-12):.0f}×"
        out.append(f"| {row['case']} | {row['triangles']:,} | {row['genus_before']} → {row['genus_after']} "
                   f"| {'—' if voxel is None else voxel['genus']} "
                   f"| {'—' if row.get('pymeshfix_genus') is None else row['pymeshfix_genus']} "
                   f"| {_signed_percent(row['area_change'])} / {_signed_percent(None if voxel is None else voxel['area_change'])} "
                   f"| {ratio} | {100 * row['kept']:.1f} % | {row['patch_aspect']:.2f} "
                   f"| {row['seconds']:.2f} s ({row['loops_seconds']:.2f} s) / "
                   f"{'—' if voxel is None else format(voxel['seconds'], '.2f') + ' s'} |")
    out += ["", "Holes: plates with k holes of 2 × 2 quads (border 8) and 4 of 4 × 4 (border 16), size 10; "
            "PyMeshFix `fill_small_boundaries(nbe=10)` and MeshLab Close Holes (up to 10 edges, refined) on the "
            "same plate. Aspect ratio R / 2r (1: equilateral); rise: the new vertices' largest distance "
            "from the plate's plane (the jitter is 0.05).", "",
            "| k | Triangles | Borders before → after: ours, PyMeshFix, MeshLab | Worst patch aspect: ours, "
            "PyMeshFix, MeshLab | Rise: ours, PyMeshFix, MeshLab | Input triangles kept: ours, PyMeshFix, MeshLab "
            "| Time: ours, PyMeshFix, MeshLab |", "|---|---|---|---|---|---|---|"]
    for row in figures["holes"]:
        tools = [row.get(n) for n in ("ours", "pymeshfix", "meshlab")]

        def cells(key, form):
            return ", ".join("—" if f is None else form(f[key]) for f in tools)

        out.append(f"| {row['k']:,} | {row['triangles']:,} | {row['borders_before']} → {cells('borders_after', str)} "
                   f"| {cells('patch_aspect', lambda v: f'{v:.2f}')} | {cells('rise', lambda v: f'{v:.3f}')} "
                   f"| {cells('kept', lambda v: f'{100 * v:.0f} %')} | {cells('seconds', lambda v: f'{v:.3f} s')} |")
    return "\n".join(out) + "\n"


def render_batch(name: str, figures: dict) -> str:
    """bench_batch.py --json: assets per minute by mode, the error report's share, the horse next to
    Blender's Decimate modifier."""
    label = f", {figures['label']}" if figures.get("label") else ""
    out = [f"## Batch throughput and the error report{label} (`{name}`)", "", *source_lines(figures),
           f"- Assets: {figures['assets']} of {figures['triangles'] // figures['assets']:,} triangles, ratio "
           f"{figures['ratio']}; outputs byte-identical across the modes: {figures['outputs_identical']}", "",
           "| mode | wall s | assets/min | overhead ms/asset | error report s of work s | with ÷ without the report | load before / after |",
           "|---|---|---|---|---|---|---|"]
    reports = {row["mode"]: row for row in figures["error_report"]}
    for row in figures["modes"]:
        report = reports[row["mode"]]
        without = max(1e-9, report["work_seconds"] - report["error_seconds"])
        out.append(f"| {row['mode']} | {row['wall_seconds']:.1f} | {row['assets_per_minute']:.0f} | "
                   f"{row['overhead_ms_per_asset']:.0f} | {report['error_seconds']:.2f} of {report['work_seconds']:.2f} | "
                   f"{report['work_seconds'] / without:.2f}× | {row['load_before']:.2f} / {row['load_after']:.2f} |")
    horse = figures.get("horse") or {}
    if "estimate" in horse:
        out += ["", "| horse, Blender batch | s per asset | error report s | hausdorff | hausdorff_upper | "
                    "Decimate modifier ÷ asset time |", "|---|---|---|---|---|---|"]
        modifier = horse.get("modifier_seconds")
        for kind, title in (("estimate", "default report"), ("exact", "--exact-error")):
            if kind not in horse:
                continue
            h = horse[kind]
            speed = f"{modifier / h['asset_seconds']:.1f}×" if modifier else "—"
            out.append(f"| {title} | {h['asset_seconds']:.2f} | {h['error_seconds']:.2f} | "
                       f"{h['lod']['hausdorff']:.4g} | {h['lod']['hausdorff_upper']:.4g} | {speed} |")
        if modifier:
            out += ["", f"Blender's Decimate modifier on the horse in the same run: {modifier:.1f} s."]
    return "\n".join(out) + "\n"


def render_report(name: str, figures: dict) -> str:
    """bench_report.py --json: the default error report's CPU time next to the decimation's, per big original."""
    label = f", {figures['label']}" if figures.get("label") else ""
    baseline = figures.get("baseline")
    out = [f"## The error report next to the decimation{label} (`{name}`)", "", *source_lines(figures)]
    if baseline:
        out.append(f"- Baseline build: `{baseline}` (same run, alternating case by case)")
    out += ["", "| case | triangles | decimation s | report s | report ÷ decimation (goal ≤ 20 %) | "
                "estimate, upper (of the diagonal) | baseline report s |", "|---|---|---|---|---|---|---|"]
    for row in figures["cases"]:
        if row.get("missing"):
            out.append(f"| {row['case']} | — (original absent) | | | | | |")
            continue
        base = f"{row['baseline']['report_seconds']:.2f}" if "baseline" in row else "—"
        settled = "" if row["converged"] else " (not converged)"
        out.append(f"| {row['case']} | {row['triangles']:,} → {row['result_triangles']:,} | "
                   f"{row['decimation_seconds']:.2f} | {row['report_seconds']:.2f} | "
                   f"{row['report_seconds'] / row['decimation_seconds']:.0%} | "
                   f"{row['estimate']:.3g}, {row['upper']:.3g}{settled} | {base} |")
    return "\n".join(out) + "\n"


def render_error_search(name: str, figures: dict) -> str:
    """bench_error_search.py --json: max_error searches against one count-target decimation at the answer."""
    cases = figures["cases"]
    with_baseline = any("baseline" in row for row in cases)
    out = [f"## Error-bounded search (`{name}`)", "",
           f"`{figures['benchmark']}`: a `max_error` search (relative to the diagonal) next to one count-target "
           "decimation at its answer, both on a fresh mesh. Issue 39's goal: the search within 3× the count "
           "target. Decimated: targets decimated; probes: their judgements (the estimate, then an exact check of some).", "",
           *source_lines(figures), "",
           "| Mesh, bound, mode | Decimated / probes | Target (failed) | Search: wall / CPU | Count target: wall / CPU "
           "| Search ÷ count (CPU) | Search CPU: decimations, exact checks, estimates (calls) |"
           + (" Baseline build (--baseline): decimated, target, search CPU, ÷ count (CPU) |" if with_baseline else ""),
           "|---|---|---|---|---|---|---|" + ("---|" if with_baseline else "")]
    for row in cases:
        split = row.get("split", {})
        parts = ", ".join(f"{split[key]['cpu']:.2f} s ({split[key]['calls']})" if key in split else "—"
                          for key in ("decimations", "exact_checks", "estimates"))
        line = (f"| {row['mesh']} {100 * row['bound']:.1f} %, {row['mode']} | {row['decimated']} / {row['probes']} "
                f"| {row['target']:,} ({row['failed']:,}) | {row['search']:.2f} s / {row['search_cpu']:.2f} s "
                f"| {row['count']:.3f} s / {row['count_cpu']:.3f} s | {row['search_cpu'] / row['count_cpu']:.1f}× | {parts} |")
        before = row.get("baseline")
        if with_baseline:
            line += (" — |" if before is None else
                     f" {before['decimated']}, {before['target']:,}, {before['search_cpu']:.2f} s, "
                     f"{before['search_cpu'] / before['count_cpu']:.1f}× |")
        out.append(line)
    return "\n".join(out) + "\n"


def render_result(path: pathlib.Path) -> str:
    figures = json.loads(path.read_text())
    if isinstance(figures, dict) and figures.get("carried_over"):
        return render_carried_over(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_decimate.py":
        return render_decimate(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_quality.py":
        return render_quality(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_loops.py --families":
        return render_loop_families(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_attributes.py":
        return render_attributes(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_scale.py":
        return render_scale(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_families.py":
        return render_families(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_high_valence.py":
        return render_high_valence(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_blender_background.py --memory":
        return render_blender_memory(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_threads_paired.py":
        return render_paired(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_cleanup.py --speed":
        return render_cleanup_speed(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_cleanup.py":
        return render_cleanup(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_blender_decimate.py --only-rest":
        return render_blender_rest(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_batch.py":
        return render_batch(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_error_search.py":
        return render_error_search(path.name, figures)
    if isinstance(figures, dict) and figures.get("benchmark") == "tests/bench/bench_report.py":
        return render_report(path.name, figures)
    raise SystemExit(f"error: {path}: no renderer for this result file (scripts/benchmarks_md.py knows "
                     "the --json of bench_decimate.py, bench_quality.py, bench_attributes.py, bench_loops.py --families, "
                     "bench_scale.py, bench_families.py, bench_high_valence.py, bench_blender_background.py --memory, bench_threads_paired.py, bench_cleanup.py, "
                     "bench_cleanup.py --speed, bench_blender_decimate.py --only-rest, bench_batch.py, bench_error_search.py and bench_report.py, and carried-over "
                     "figures)")


def render() -> str:
    """The whole of docs/benchmarks.md."""
    parts = [HEADER]
    parts += [render_result(path) for path in sorted(RESULTS.glob("*.json"))]
    parts += [path.read_text().rstrip("\n") + "\n" for path in sorted(NOTES.glob("*.md"))]
    return "\n".join(parts)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="only compare; exit 1 when out of date")
    args = parser.parse_args()
    text = render()
    if args.check:
        if not OUTPUT.exists() or OUTPUT.read_text() != text:
            print(f"{OUTPUT.relative_to(ROOT)} is out of date: run python3 scripts/benchmarks_md.py", file=sys.stderr)
            return 1
        return 0
    temporary = OUTPUT.with_suffix(".md.tmp")
    temporary.write_text(text)
    temporary.replace(OUTPUT)  # atomic: never a half-written file under the final name
    return 0


if __name__ == "__main__":
    sys.exit(main())
