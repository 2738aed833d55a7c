"""Independent reference routines for tests: plain numpy, no topstoc code.

Used to check what the engine produces against a second, simple implementation.
"""

import numpy as np


def undirected_edges(triangles):
    t = np.asarray(triangles, dtype=np.int64)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    return np.sort(e, axis=1)


def components(num_vertices, triangles):
    """Component id per vertex (-1 for vertices in no triangle), by union-find over edges."""
    parent = np.arange(num_vertices)

    def find(x):
        root = x
        while parent[root] != root:
            root = parent[root]
        while parent[x] != root:
            parent[x], x = root, parent[x]
        return root

    for a, b in undirected_edges(triangles):
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    used = np.zeros(num_vertices, dtype=bool)
    used[np.asarray(triangles).ravel()] = True
    roots = np.array([find(v) for v in range(num_vertices)])
    ids = {r: i for i, r in enumerate(sorted(set(roots[used])))}
    return np.array([ids[r] if used[v] else -1 for v, r in enumerate(roots)])


def invariants(num_vertices, triangles):
    """Per component (sorted): (euler characteristic, boundary loops, manifold, orientable)."""
    tri = np.asarray(triangles, dtype=np.int64)
    comp = components(num_vertices, tri)
    edges, counts = np.unique(undirected_edges(tri), axis=0, return_counts=True)
    result = []
    for c in range(comp.max() + 1 if len(tri) else 0):
        vs = np.flatnonzero(comp == c)
        es = edges[comp[edges[:, 0]] == c]
        ks = counts[comp[edges[:, 0]] == c]
        fs = tri[comp[tri[:, 0]] == c]
        chi = len(vs) - len(es) + len(fs)
        boundary = es[ks == 1]
        # boundary loops = connected components of the boundary edge graph
        loops = 0
        if len(boundary):
            sub = {int(v): i for i, v in enumerate(np.unique(boundary))}
            parent = list(range(len(sub)))

            def find(x):
                while parent[x] != x:
                    parent[x] = parent[parent[x]]
                    x = parent[x]
                return x

            for a, b in boundary:
                ra, rb = find(sub[int(a)]), find(sub[int(b)])
                if ra != rb:
                    parent[ra] = rb
            loops = len({find(i) for i in range(len(sub))})
        manifold = bool(np.all(ks <= 2)) and vertex_manifold(fs)
        result.append((int(chi), loops, manifold, orientable(fs) if manifold else None))
    return sorted(result, key=lambda x: (x[0], x[1]))


def vertex_manifold(triangles):
    """Every vertex's triangles form one fan (connected through shared edges)."""
    tri = np.asarray(triangles, dtype=np.int64)
    by_vertex = {}
    for f, t in enumerate(tri):
        for v in t:
            by_vertex.setdefault(int(v), []).append(f)
    for v, fs in by_vertex.items():
        seen = {fs[0]}
        stack = [fs[0]]
        while stack:
            f = stack.pop()
            for g in fs:
                if g not in seen and len(set(tri[f]) & set(tri[g])) == 2:
                    seen.add(g)
                    stack.append(g)
        if len(seen) != len(fs):
            return False
    return True


def orientable(triangles):
    """Consistent orientation exists (each interior edge used once in each direction after flips)."""
    tri = [list(map(int, t)) for t in triangles]
    edge_faces = {}
    for f, t in enumerate(tri):
        for i in range(3):
            a, b = t[i], t[(i + 1) % 3]
            edge_faces.setdefault((min(a, b), max(a, b)), []).append((f, a < b))
    flip = [None] * len(tri)
    for start in range(len(tri)):
        if flip[start] is not None:
            continue
        flip[start] = False
        stack = [start]
        while stack:
            f = stack.pop()
            t = tri[f]
            for i in range(3):
                a, b = t[i], t[(i + 1) % 3]
                for g, forward in edge_faces[(min(a, b), max(a, b))]:
                    if g == f:
                        continue
                    # f traverses a->b (forward if a<b), flipped if flip[f]
                    f_forward = (a < b) != flip[f]
                    want = not f_forward  # neighbour must traverse the other way
                    g_flip = forward != want
                    if flip[g] is None:
                        flip[g] = g_flip
                        stack.append(g)
                    elif flip[g] != g_flip:
                        return False
    return True


def euler_genus(chi, boundary_loops):
    """Genus of an orientable surface from chi = 2 - 2g - b."""
    return (2 - chi - boundary_loops) // 2


def cut_along(triangles, cut_edges):
    """Cuts a surface along edges: each vertex is split into one copy per group of its corners
    that stay joined across uncut edges shared by exactly two triangles. Returns (number of
    vertices, triangles) of the cut surface."""
    tri = np.asarray(triangles, dtype=np.int64)
    cut = {(min(a, b), max(a, b)) for a, b in np.asarray(cut_edges).tolist()}
    parent = list(range(3 * len(tri)))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    sides = {}
    for f, t in enumerate(tri.tolist()):
        for k in range(3):
            a, b = t[k], t[(k + 1) % 3]
            sides.setdefault((min(a, b), max(a, b)), []).append(f)
    for edge, faces in sides.items():
        if edge in cut or len(faces) != 2:
            continue
        f, g = faces
        for v in edge:  # the corners of v in f and g are one vertex of the cut surface
            cf = 3 * f + tri[f].tolist().index(v)
            cg = 3 * g + tri[g].tolist().index(v)
            parent[find(cf)] = find(cg)
    ids = {}
    out = np.empty_like(tri)
    for f in range(len(tri)):
        for k in range(3):
            out[f, k] = ids.setdefault(find(3 * f + k), len(ids))
    return len(ids), out


def gf2_rank(vectors):
    """Rank over Z2 of bit vectors given as Python ints."""
    pivots = {}
    rank = 0
    for v in vectors:
        while v:
            top = v.bit_length() - 1
            if top in pivots:
                v ^= pivots[top]
            else:
                pivots[top] = v
                rank += 1
                break
    return rank


def homology_rank(triangles, cycles):
    """Number of independent classes the cycles (closed vertex sequences) span in H1 over Z2:
    rank(boundaries + cycles) - rank(boundaries)."""
    tri = np.asarray(triangles, dtype=np.int64)
    index = {}

    def bit(a, b):
        return 1 << index.setdefault((min(a, b), max(a, b)), len(index))

    boundaries = [bit(a, b) ^ bit(b, c) ^ bit(c, a) for a, b, c in tri.tolist()]
    chains = []
    for cycle in cycles:
        cycle = list(cycle)
        chain = 0
        for i in range(len(cycle)):
            chain ^= bit(cycle[i], cycle[(i + 1) % len(cycle)])
        chains.append(chain)
    base = gf2_rank(boundaries)
    return gf2_rank(boundaries + chains) - base
