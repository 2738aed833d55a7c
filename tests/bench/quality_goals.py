"""Issue 40's two quality figures for one bench_quality.py case, shared by the benchmark and
scripts/benchmarks_md.py: our mean over the better of Blender and MeshLab, our max over the best
peer, each peer taken only where it reached our triangle count."""

from __future__ import annotations

PEERS = ("Blender Collapse", "MeshLab", "meshopt_simplify", "fast-simplification")

# Errors below this (in % of the diagonal: 1e-8 of it, below the rounding of a float32 output)
# count as exact: the ratio of two such figures (a flat mesh all tools keep flat) measures
# rounding, not quality.
EXACT = 1e-6

# A peer asked for our count that returns more than this share above it (plus two triangles of
# rounding) stopped at a floor of its own: its errors are a larger mesh's, not a rival at our count.
COUNT_SLACK = 0.05


def error_ratio(ours: float, peer: float) -> float:
    return max(ours, EXACT) / max(peer, EXACT)


def at_our_count(ours: dict, peer: dict | None) -> bool:
    return bool(peer) and peer["triangles"] <= ours["triangles"] * (1 + COUNT_SLACK) + 2


def goal_ratios(case: dict, mode: str = "quality", kept_topology: bool = False) -> tuple[float | None, float | None]:
    """(mean ÷ the better of Blender and MeshLab, max ÷ the best peer) of our result in ``mode``,
    None where no such peer reached our count (the peers decimate to the quality result's count,
    which the best mode's result shares: its fit only moves vertices). kept_topology: only the
    peers whose result kept every component's topology, as ours does, enter."""
    tools = case["tools"]
    ours = tools.get(f"topstoc {mode}")
    if not ours:
        return None, None

    def rival(name: str) -> bool:
        peer = tools.get(name)
        return at_our_count(ours, peer) and (not kept_topology or bool(peer.get("topology")))

    means = [tools[n]["mean"] for n in ("Blender Collapse", "MeshLab") if rival(n)]
    maxes = [tools[n]["max"] for n in PEERS if rival(n)]
    return (error_ratio(ours["mean"], min(means)) if means else None,
            error_ratio(ours["max"], min(maxes)) if maxes else None)


def left_out(case: dict) -> list[str]:
    """The peers that ran but stopped above our count."""
    tools = case["tools"]
    ours = tools.get("topstoc quality")
    return [n for n in PEERS if ours and tools.get(n) and not at_our_count(ours, tools[n])]
