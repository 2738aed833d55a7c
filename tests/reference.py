"""Independent reference routines for tests: numpy and scipy only, no topstoc code.

Used to check what the engine produces against a second, plain implementation.
"""

import gzip
import bz2

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def read_off(path):
    """Minimal OFF reader (one element per line, polygons fan-triangulated), independent of
    topstoc's readers."""
    data = open(path, "rb").read()
    if str(path).endswith(".gz"):
        data = gzip.decompress(data)
    elif str(path).endswith(".bz2"):
        data = bz2.decompress(data)
    lines = [line.split("#")[0].split() for line in data.decode("latin-1").splitlines()]
    lines = [line for line in lines if line]
    header = lines[0]
    assert header[0].endswith("OFF"), path
    counts, rest = (header[1:], lines[1:]) if len(header) > 1 else (lines[1], lines[2:])
    nv, nf = int(counts[0]), int(counts[1])
    vertices = np.array([[float(x) for x in line[:3]] for line in rest[:nv]], dtype=float).reshape(nv, 3)
    triangles = []
    for line in rest[nv:nv + nf]:
        k = int(line[0])
        poly = [int(x) for x in line[1:1 + k]]
        for i in range(1, k - 1):
            triangles.append((poly[0], poly[i], poly[i + 1]))
    return vertices, np.array(triangles, dtype=np.int64).reshape(-1, 3)


def _graph_components(num_nodes, a, b):
    if num_nodes == 0:
        return 0, np.zeros(0, dtype=np.int64)
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(num_nodes, num_nodes))
    return connected_components(graph, directed=False)


def undirected_edges(triangles):
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    return np.sort(e, axis=1)


def components(num_vertices, triangles):
    """Component id per vertex (-1 for vertices in no triangle)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    e = undirected_edges(t)
    _, comp = _graph_components(num_vertices, e[:, 0], e[:, 1])
    used = np.zeros(num_vertices, dtype=bool)
    used[t.ravel()] = True
    # renumber the components that hold triangles as 0, 1, ... in order of first vertex
    ids = {}
    out = np.full(num_vertices, -1)
    for v in np.flatnonzero(used):
        out[v] = ids.setdefault(comp[v], len(ids))
    return out


def _corner_fans(triangles):
    """Component id of every corner (3 per triangle) in the graph that joins the corners of a
    vertex across edges shared by exactly two triangles: one component per fan."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    m = len(t)
    sides = []  # (edge key, face, corner of the edge's start, corner of the edge's end)
    for j in range(3):
        a, b = t[:, j], t[:, (j + 1) % 3]
        key = np.minimum(a, b) * (t.max() + 1) + np.maximum(a, b)
        start = np.where(a < b, 3 * np.arange(m) + j, 3 * np.arange(m) + (j + 1) % 3)
        end = np.where(a < b, 3 * np.arange(m) + (j + 1) % 3, 3 * np.arange(m) + j)
        sides.append(np.stack([key, start, end], 1))
    sides = np.concatenate(sides)
    order = np.argsort(sides[:, 0], kind="stable")
    sides = sides[order]
    keys, starts, counts = np.unique(sides[:, 0], return_index=True, return_counts=True)
    pairs = starts[counts == 2]
    first, second = sides[pairs], sides[pairs + 1]
    a = np.concatenate([first[:, 1], first[:, 2]])
    b = np.concatenate([second[:, 1], second[:, 2]])
    _, labels = _graph_components(3 * m, a, b)
    return labels


def invariants(num_vertices, triangles):
    """Per component, sorted: (euler characteristic, boundary loops, manifold, orientable).

    Manifold: every edge in at most two triangles and every vertex's triangles one fan.
    Orientable: the triangles can be oriented consistently (None when not manifold).
    """
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if len(t) == 0:
        return []
    comp = components(num_vertices, t)
    edges, counts = np.unique(undirected_edges(t), axis=0, return_counts=True)
    fans = _corner_fans(t)
    vertex_of_corner = t.ravel()
    fans_per_vertex = np.zeros(num_vertices, dtype=np.int64)
    unique_pairs = np.unique(np.stack([vertex_of_corner, fans], 1), axis=0)
    np.add.at(fans_per_vertex, unique_pairs[:, 0], 1)
    boundary = edges[counts == 1]
    _, boundary_comp = _graph_components(num_vertices, boundary[:, 0], boundary[:, 1])
    orientable_faces = _orientable_faces(t, edges, counts)
    result = []
    for c in range(comp.max() + 1):
        vs = np.flatnonzero(comp == c)
        in_c = comp[edges[:, 0]] == c
        faces_c = comp[t[:, 0]] == c
        chi = len(vs) - int(in_c.sum()) + int(faces_c.sum())
        b = boundary[comp[boundary[:, 0]] == c]
        loops = len(np.unique(boundary_comp[b[:, 0]])) if len(b) else 0
        manifold = bool(np.all(counts[in_c] <= 2) and np.all(fans_per_vertex[vs] == 1))
        result.append((int(chi), int(loops), manifold,
                       bool(np.all(orientable_faces[faces_c])) if manifold else None))
    return sorted(result, key=lambda x: (x[0], x[1], x[2]))


def _orientable_faces(t, edges, counts):
    """Per face: whether its component can be oriented consistently (signed-graph balance).

    Each face f becomes two nodes f+ and f-; across an edge shared by two faces, the faces
    are consistent when they traverse the edge in opposite directions (join f+ g+ and f- g-),
    otherwise one must flip (join f+ g- and f- g+). A component is orientable exactly when no
    face ends up joined to its own opposite."""
    m = len(t)
    a_list, b_list = [], []
    sides = []
    for j in range(3):
        a, b = t[:, j], t[:, (j + 1) % 3]
        key = np.minimum(a, b) * (t.max() + 1) + np.maximum(a, b)
        sides.append(np.stack([key, np.arange(m), (a < b).astype(np.int64)], 1))
    sides = np.concatenate(sides)
    sides = sides[np.argsort(sides[:, 0], kind="stable")]
    _, starts, cnt = np.unique(sides[:, 0], return_index=True, return_counts=True)
    pairs = starts[cnt == 2]
    f, g = sides[pairs, 1], sides[pairs + 1, 1]
    same_direction = sides[pairs, 2] == sides[pairs + 1, 2]
    plus = lambda x: 2 * x  # noqa: E731
    minus = lambda x: 2 * x + 1  # noqa: E731
    a_list = np.concatenate([np.where(same_direction, plus(f), plus(f)), np.where(same_direction, minus(f), minus(f))])
    b_list = np.concatenate([np.where(same_direction, minus(g), plus(g)), np.where(same_direction, plus(g), minus(g))])
    _, labels = _graph_components(2 * m, a_list, b_list)
    return labels[0::2] != labels[1::2]


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


def aspect_ratios(vertices, triangles):
    """Thesis eq. 4.2 per triangle: e0 e1 e2 / (8 (s - e0)(s - e1)(s - e2)); inf when degenerate."""
    p = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    e = np.stack([np.linalg.norm(p[:, 1] - p[:, 2], axis=1), np.linalg.norm(p[:, 2] - p[:, 0], axis=1),
                  np.linalg.norm(p[:, 0] - p[:, 1], axis=1)], axis=1)
    s = e.sum(axis=1) / 2
    denominator = 8 * (s - e[:, 0]) * (s - e[:, 1]) * (s - e[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(denominator > 0, e.prod(axis=1) / denominator, np.inf)


def degenerate_or_duplicate(triangles):
    """(number of triangles with a repeated vertex, number of repeated vertex sets)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    degenerate = int(np.sum((t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])))
    duplicates = len(t) - len(np.unique(np.sort(t, axis=1), axis=0))
    return degenerate, duplicates


def area_weighted_normals(vertices, triangles):
    """Unit vertex normals from the sum of (unnormalised) face cross products."""
    v = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles, dtype=np.int64)
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    out = np.zeros_like(v)
    for j in range(3):
        np.add.at(out, t[:, j], n)
    length = np.linalg.norm(out, axis=1, keepdims=True)
    return np.divide(out, length, out=np.zeros_like(out), where=length > 0)


def importance_weights(vertices, triangles):
    """Thesis eq. 4.1 over the one-ring of vertex neighbours."""
    normals = area_weighted_normals(vertices, triangles)
    e = np.unique(undirected_edges(triangles), axis=0)
    n = len(vertices)
    dots = np.einsum("ij,ij->i", normals[e[:, 0]], normals[e[:, 1]])
    total = np.zeros(n)
    degree = np.zeros(n)
    np.add.at(total, e[:, 0], dots)
    np.add.at(total, e[:, 1], dots)
    np.add.at(degree, e[:, 0], 1)
    np.add.at(degree, e[:, 1], 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        x = (degree - total) / (2 * degree)
    return np.clip(np.nan_to_num(x), 0, 1)
