"""Carrying flagged edges (UV seams, sharp edges) from the input to a decimated output.

Output edges are new edges between kept input vertices, so an input edge flag cannot be copied
edge by edge. When the flags were borders (Keep UV Seams, Keep Sharp Edges) the engine samples
each flagged curve as a curve of its own: consecutive samples of one curve are joined by an
output edge, and the input vertices between them were dropped. The rule, on input vertex ids:

    output edge (a, b) is flagged  <=>  kept[a] and kept[b] are joined by one flagged input
    edge, or by a path of flagged input edges whose inner vertices are all not kept.

A vertex counts as kept when some output vertex stands on it: a ``kept`` entry that is negative
(absent) or belongs to a ``moved`` output vertex (quality mode placed it elsewhere; it is not a
sample of the curve) counts for nothing, and that output vertex's edges are never flagged. So a
chain may pass through a moved vertex's input vertex. At a junction (3+ flagged edges) or a
closed curve nothing is special: the chains are the flagged paths between kept vertices. Pinched
vertices are always kept (several output vertices may name one input vertex; the rule holds on
input ids). When the flags were not borders, the output rarely holds the chains' edges and few
edges are flagged, which is right: the curve did not survive.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from ..support.errors import TopStocError


class EdgeFlagError(TopStocError):
    """Edge flags that cannot be carried (malformed arrays)."""


def carried_edge_flags(flagged, edges, kept, moved: Optional[np.ndarray] = None) -> np.ndarray:
    """Boolean per output edge: whether it carries the flag of ``flagged`` (the rule above).

    flagged: (k, 2) input vertex pairs of the flagged input edges (any order, repeats allowed);
    edges: (e, 2) output vertex pairs; kept: (n_out,) input vertex of each output vertex
    (negative: none); moved: optional (n_out,) bool, output vertices not at their input vertex.
    Runs in O((k + e) log k) numpy operations (no per-edge Python loop).
    """
    flagged = _pairs(flagged, "flagged")
    edges = _pairs(edges, "edges")
    kept = np.asarray(kept, dtype=np.int64).reshape(-1)
    if len(edges) and (edges.min() < 0 or edges.max() >= len(kept)):
        raise EdgeFlagError(f"an output edge names a vertex outside [0, {len(kept)})")
    if flagged.size and flagged.min() < 0:
        raise EdgeFlagError("a flagged edge names a negative vertex id")
    usable = kept >= 0
    if moved is not None:
        moved = np.asarray(moved, dtype=bool).reshape(-1)
        if len(moved) != len(kept):
            raise EdgeFlagError(f"moved has {len(moved)} entries for {len(kept)} output vertices")
        usable &= ~moved
    out = np.zeros(len(edges), dtype=bool)
    flagged = flagged[flagged[:, 0] != flagged[:, 1]]
    if len(flagged) == 0 or len(edges) == 0:
        return out
    count = int(max(flagged.max(), kept.max(initial=-1))) + 1
    is_kept = np.zeros(count, dtype=bool)
    is_kept[kept[usable]] = True

    a, b = edges[:, 0], edges[:, 1]
    live = usable[a] & usable[b] & (kept[a] != kept[b])
    u, v = np.minimum(kept[a], kept[b]), np.maximum(kept[a], kept[b])

    # one flagged input edge
    lo, hi = flagged.min(axis=1), flagged.max(axis=1)
    direct = np.unique(lo * count + hi)
    out |= live & _member(u * count + v, direct)

    # a chain: kept ends attached to one component of the not-kept flagged subgraph
    inner = ~is_kept[lo] & ~is_kept[hi]
    label = _components(count, lo[inner], hi[inner])
    one_end = is_kept[lo] ^ is_kept[hi]
    end = np.where(is_kept[lo], lo, hi)[one_end]            # the kept end
    chain = label[np.where(is_kept[lo], hi, lo)[one_end]]   # the component it enters
    attached = np.unique(end * count + chain)                # sorted (kept vertex, component) keys
    if len(attached) == 0:
        return out
    owner = attached // count
    # for every live output edge, each component u is attached to: is v attached to it too?
    rows = np.flatnonzero(live)
    first = np.searchsorted(owner, u[rows], side="left")
    degree = np.searchsorted(owner, u[rows], side="right") - first
    row = np.repeat(rows, degree)
    offset = np.arange(len(row)) - np.repeat(np.cumsum(degree) - degree, degree)
    component = attached[np.repeat(first, degree) + offset] % count
    hit = _member(v[row] * count + component, attached)
    out[row[hit]] = True
    return out


def _pairs(values, name: str) -> np.ndarray:
    pairs = np.asarray(values, dtype=np.int64)
    if pairs.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    if pairs.ndim != 2 or pairs.shape[1] != 2:
        raise EdgeFlagError(f"{name} must be (k, 2) vertex pairs, got shape {pairs.shape}")
    return pairs


def _member(keys: np.ndarray, sorted_keys: np.ndarray) -> np.ndarray:
    """keys in sorted_keys (sorted, unique)."""
    if len(sorted_keys) == 0:
        return np.zeros(len(keys), dtype=bool)
    at = np.minimum(np.searchsorted(sorted_keys, keys), len(sorted_keys) - 1)
    return sorted_keys[at] == keys


def _components(count: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Connected-component label (the smallest vertex id) of every vertex of the graph with
    edges (a, b): roots hook onto the smaller root across every edge joining two trees, then
    pointer jumping flattens the trees; a path of length L takes O(log L) rounds."""
    label = np.arange(count, dtype=np.int64)
    while True:
        la, lb = label[a], label[b]
        differ = la != lb
        if not differ.any():
            return label
        np.minimum.at(label, np.maximum(la, lb)[differ], np.minimum(la, lb)[differ])
        while True:
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped
