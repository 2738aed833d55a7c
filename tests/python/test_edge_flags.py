"""Carried edge flags (core/carry/edge_flags.py) against a brute-force search of the flagged paths."""

from collections import defaultdict, deque

import numpy as np
import pytest

from topstoc.core.carry.edge_flags import EdgeFlagError, carried_edge_flags
from topstoc.core.support.errors import TopStocError


def reference(flagged, edges, kept, moved=None):
    """Per output edge: a breadth-first search from kept[a] along flagged input edges that never
    passes through a kept input vertex, reaching kept[b] (the rule, edge by edge)."""
    kept = [int(k) for k in kept]
    usable = [k >= 0 and (moved is None or not moved[i]) for i, k in enumerate(kept)]
    kept_set = {k for k, ok in zip(kept, usable) if ok}
    neighbours = defaultdict(set)
    for p, q in np.asarray(flagged).reshape(-1, 2).tolist():
        if p != q:
            neighbours[p].add(q)
            neighbours[q].add(p)
    out = []
    for a, b in np.asarray(edges).reshape(-1, 2).tolist():
        if not (usable[a] and usable[b]) or kept[a] == kept[b]:
            out.append(False)
            continue
        start, goal = kept[a], kept[b]
        seen, queue, found = {start}, deque([start]), False
        while queue and not found:
            x = queue.popleft()
            for y in neighbours[x]:
                if y == goal:
                    found = True
                    break
                if y not in seen and y not in kept_set:
                    seen.add(y)
                    queue.append(y)
        out.append(found)
    return np.array(out, dtype=bool)


def grid_curves(rng, size, curves, closed_every=3):
    """Flagged edges of random walks on a size x size grid (vertex id = row * size + column);
    every ``closed_every``-th walk is a closed square loop. Walks cross and touch: junctions."""
    flagged = []
    for c in range(curves):
        if c % closed_every == 0:
            r, s = rng.integers(0, size - 3, 2)
            w = int(rng.integers(2, min(6, size - max(r, s))))
            ring = [(r, s + i) for i in range(w)] + [(r + i, s + w) for i in range(w)] + \
                   [(r + w, s + w - i) for i in range(w)] + [(r + w - i, s) for i in range(w)]
            points = ring + ring[:1]
        else:
            p = rng.integers(0, size, 2)
            points = [tuple(p)]
            for _ in range(int(rng.integers(3, 3 * size))):
                step = [(0, 1), (0, -1), (1, 0), (-1, 0)][rng.integers(4)]
                q = (min(max(points[-1][0] + step[0], 0), size - 1), min(max(points[-1][1] + step[1], 0), size - 1))
                if q != points[-1]:
                    points.append(q)
        flagged += [(p[0] * size + p[1], q[0] * size + q[1]) for p, q in zip(points, points[1:])]
    return np.array(flagged, dtype=np.int64)


@pytest.mark.parametrize("seed", range(40))
def test_random_curves_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    size = int(rng.integers(5, 14))
    flagged = grid_curves(rng, size, int(rng.integers(1, 6)))
    rng.shuffle(flagged, axis=0)
    swap = rng.random(len(flagged)) < 0.5
    flagged[swap] = flagged[swap][:, ::-1]
    n = size * size
    on_curves = np.unique(flagged)
    sampled = np.union1d(on_curves[rng.random(len(on_curves)) < rng.uniform(0.1, 0.6)],  # samples of the curves
                         rng.choice(on_curves, 3))
    others = rng.permutation(n)[: int(rng.integers(0, 10))]
    kept = rng.permutation(np.union1d(sampled, others))[:70]                   # all pairs: <= 2415 edges
    if seed % 4 == 0:
        kept = np.concatenate([kept, kept[:3]])                   # an input vertex behind two outputs
    if seed % 5 == 0:
        kept[rng.integers(len(kept))] = -1                        # an absent entry
    moved = rng.random(len(kept)) < 0.1 if seed % 3 == 0 else None
    # output edges: every pair of output vertices, so every pair the rule flags is asked
    pairs = np.array([(i, j) for i in range(len(kept)) for j in range(i + 1, len(kept))], dtype=np.int64)
    edges = pairs[:, ::-1] if seed % 2 else pairs
    got = carried_edge_flags(flagged, edges, kept, moved)
    want = reference(flagged, edges, kept, moved)
    np.testing.assert_array_equal(got, want)
    assert want.any()  # the case is not trivially all False


def chain(ids):
    return np.array(list(zip(ids, ids[1:])), dtype=np.int64)


def test_chain_whose_inner_vertices_are_dropped():
    flagged = chain([0, 1, 2, 3, 4, 5, 6])
    kept = np.array([0, 3, 6, 9])                                # output vertices 0..3
    edges = np.array([[0, 1], [1, 2], [0, 2], [2, 3], [0, 3]])
    np.testing.assert_array_equal(carried_edge_flags(flagged, edges, kept), [True, True, False, False, False])
    # 0 -> 6 is a chain only when 3 is dropped too
    np.testing.assert_array_equal(carried_edge_flags(flagged, [[0, 1]], [0, 6]), [True])


def test_closed_loop():
    loop = chain([0, 1, 2, 3, 4, 5, 6, 7, 0])
    kept = np.array([0, 2, 5])
    edges = np.array([[0, 1], [1, 2], [2, 0]])
    np.testing.assert_array_equal(carried_edge_flags(loop, edges, kept), [True, True, True])
    # one kept vertex on the loop: the loop joins it only to itself (no output edge)
    np.testing.assert_array_equal(carried_edge_flags(loop, [[0, 1]], [0, 10]), [False])


def test_junction():
    # three arms meet at 0: 0-1-2, 0-3-4, 0-5-6
    flagged = np.concatenate([chain([0, 1, 2]), chain([0, 3, 4]), chain([0, 5, 6])])
    kept = np.array([0, 2, 4, 6])
    edges = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
    np.testing.assert_array_equal(carried_edge_flags(flagged, edges, kept), [True, True, True, False, False, False])
    # the junction dropped: every pair of arm ends is joined through it
    np.testing.assert_array_equal(carried_edge_flags(flagged, [[0, 1], [1, 2], [0, 2]], [2, 4, 6]), [True] * 3)


def test_pinched_vertex_and_moved_or_absent_entries():
    flagged = chain([0, 1, 2, 3, 4])
    kept = np.array([0, 2, 2, 4, -1])   # input 2 (a pinched vertex) stands behind outputs 1 and 2
    edges = np.array([[0, 1], [0, 2], [2, 3], [1, 2], [3, 4], [0, 4]])
    np.testing.assert_array_equal(carried_edge_flags(flagged, edges, kept), [True, True, True, False, False, False])
    moved = np.array([False, True, True, False, False])   # input 2 no longer sampled: 0 joins 4
    np.testing.assert_array_equal(carried_edge_flags(flagged, [[0, 1], [0, 3]], kept, moved), [False, True])


def test_nothing_flagged_and_direct_edges():
    assert not carried_edge_flags(np.zeros((0, 2)), [[0, 1]], [0, 1]).any()
    assert carried_edge_flags([[5, 7]], np.zeros((0, 2)), [5, 7]).shape == (0,)
    np.testing.assert_array_equal(carried_edge_flags([[7, 5], [3, 3]], [[1, 0], [0, 2]], [5, 7, 3]), [True, False])


def test_bad_input_is_named():
    with pytest.raises(EdgeFlagError, match="outside"):
        carried_edge_flags([[0, 1]], [[0, 2]], [0, 1])
    with pytest.raises(EdgeFlagError, match="pairs"):
        carried_edge_flags([0, 1, 2], [[0, 1]], [0, 1])
    with pytest.raises(EdgeFlagError, match="moved"):
        carried_edge_flags([[0, 1]], [[0, 1]], [0, 1], moved=[True])
    assert issubclass(EdgeFlagError, TopStocError)
