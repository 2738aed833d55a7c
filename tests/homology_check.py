"""Independent homology checks for handle and tunnel loops: GUDHI and numpy, no topstoc code.

A loop is null-homologous in a complex K exactly when coning it off (a new apex joined to each
of its edges) leaves the first Betti number of K unchanged; a set of loops spans a subspace of
H1(K) of rank r exactly when coning all of them off lowers the first Betti number by r.
"""

import numpy as np

try:
    import gudhi
except ImportError:  # pragma: no cover - python3-gudhi is a test dependency
    gudhi = None


def betti(simplices, field=2):
    """Betti numbers (b0, b1, b2, ...) over Z_field of the complex spanned by the given
    simplices (a list of (k, d+1) integer arrays; all faces are added)."""
    tree = gudhi.SimplexTree()
    for array in simplices:
        array = np.asarray(array, dtype=np.int64)
        if len(array):
            tree.insert_batch(array.T, np.zeros(len(array)))
    tree.compute_persistence(homology_coeff_field=field, persistence_dim_max=True)
    numbers = list(tree.betti_numbers())
    return numbers + [0] * (4 - len(numbers))


def cones(loops, first_apex):
    """Triangles coning off each loop (a closed vertex sequence) with its own apex."""
    triangles = []
    for i, loop in enumerate(loops):
        loop = np.asarray(loop, dtype=np.int64)
        apex = np.full(len(loop), first_apex + i)
        triangles.append(np.stack([apex, loop, np.roll(loop, -1)], axis=1))
    return np.concatenate(triangles) if triangles else np.zeros((0, 3), dtype=np.int64)


def coned_b1(base, loops, first_apex, field=2):
    """First Betti number of the complex `base` (list of simplex arrays) with `loops` coned off."""
    return betti(list(base) + [cones(loops, first_apex)], field)[1]


def is_simple_edge_cycle(loop, triangles):
    """True when the loop is a closed cycle of edges of the triangles visiting no vertex twice."""
    loop = np.asarray(loop)
    if len(loop) < 3 or len(np.unique(loop)) != len(loop):
        return False
    t = np.asarray(triangles, dtype=np.int64)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    n = int(max(edges.max(), loop.max())) + 1
    known = set((edges[:, 0] * n + edges[:, 1]).tolist())
    steps = np.sort(np.stack([loop, np.roll(loop, -1)], axis=1), axis=1)
    return all(int(a) * n + int(b) in known for a, b in steps)


def loop_length(vertices, loop):
    p = np.asarray(vertices)[np.asarray(loop)]
    return float(np.linalg.norm(p - np.roll(p, -1, axis=0), axis=1).sum())


def winding_numbers(vertices, triangles, points):
    """Generalized winding number of a closed triangle mesh at each point (solid angles)."""
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    out = []
    for p in np.asarray(points, dtype=np.float64):
        a, b, c = v[t[:, 0]] - p, v[t[:, 1]] - p, v[t[:, 2]] - p
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la \
            + np.einsum("ij,ij->i", c, a) * lb
        out.append(np.sum(2 * np.arctan2(det, den)) / (4 * np.pi))
    return np.array(out)
