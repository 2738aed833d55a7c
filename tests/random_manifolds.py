"""Random valid manifolds with known topology, and an independent check of a decimation's
output against its input (numpy and scipy only, no topstoc code).

A deterministic generator (numpy's PCG64 from a seed) instead of hypothesis: the same seed
always gives the same mesh, so any failure found by the stress script is reproducible from two
numbers, and CI needs nothing from PyPI.
"""

import numpy as np
from scipy.spatial import ConvexHull


def hull(rng):
    """Convex hull of 6..160 random points on an ellipsoid: a sphere (genus 0)."""
    n = int(rng.integers(6, 160))
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    p *= rng.uniform(0.3, 2.0, size=3)
    h = ConvexHull(p)
    t = h.simplices.copy()
    centre = p.mean(axis=0)
    normal = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    flip = np.einsum("ij,ij->i", normal, p[t[:, 0]] - centre) < 0
    t[flip] = t[flip][:, [0, 2, 1]]
    used = np.unique(t)
    remap = np.full(n, -1)
    remap[used] = np.arange(len(used))
    return p[used], remap[t]


def torus(rng):
    """A torus as an nu x nv grid (3..24 x 3..12), jittered: genus 1."""
    nu, nv = int(rng.integers(3, 25)), int(rng.integers(3, 13))
    major = rng.uniform(1.0, 2.0)
    minor = rng.uniform(0.15, 0.8) * major
    u = np.arange(nu) * 2 * np.pi / nu + rng.uniform(-0.2, 0.2, nu) * np.pi / nu
    v = np.arange(nv) * 2 * np.pi / nv
    uu, vv = np.meshgrid(u, v, indexing="ij")
    p = np.stack([(major + minor * np.cos(vv)) * np.cos(uu), (major + minor * np.cos(vv)) * np.sin(uu),
                  minor * np.sin(vv)], -1).reshape(-1, 3)
    p += rng.normal(scale=0.02 * minor, size=p.shape)
    idx = lambda i, j: (i % nu) * nv + (j % nv)  # noqa: E731
    t = []
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            t += [(a, b, c), (a, c, d)] if rng.random() < 0.5 else [(a, b, d), (b, c, d)]
    return p, np.array(t)


def grid_with_holes(rng):
    """An n x m grid (3..20) with up to 6 square holes that share no vertex with each other or
    the border, bent in z: a disk with `holes` holes (1 + holes boundary loops)."""
    n, m = int(rng.integers(3, 21)), int(rng.integers(3, 21))
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=float), np.arange(m + 1, dtype=float), indexing="ij")
    z = rng.uniform(0, 0.8) * np.sin(xs * rng.uniform(0.2, 1.5)) + rng.uniform(0, 0.5) * np.cos(ys)
    p = np.stack([xs, ys, z], -1).reshape(-1, 3) + rng.normal(scale=0.05, size=((n + 1) * (m + 1), 3))
    cells = [(i, j) for i in range(1, n - 1, 2) for j in range(1, m - 1, 2)]
    rng.shuffle(cells)
    holes = set(map(tuple, cells[:int(rng.integers(0, 7))]))
    idx = lambda i, j: i * (m + 1) + j  # noqa: E731
    t = []
    for i in range(n):
        for j in range(m):
            if (i, j) in holes:
                continue
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            t += [(a, b, c), (a, c, d)] if rng.random() < 0.5 else [(a, b, d), (b, c, d)]
    return p, np.array(t)


def icosphere(rng):
    """An icosahedron subdivided 0..2 times, radially jittered: a sphere."""
    from meshgen import icosphere as sphere
    p, t = sphere(int(rng.integers(0, 3)))
    return p * rng.uniform(0.8, 1.2, size=(len(p), 1)), t


KINDS = (hull, torus, grid_with_holes, icosphere)


def random_manifold(seed):
    """1..4 random surfaces side by side, vertices and triangles shuffled, corners rotated."""
    rng = np.random.default_rng(seed)
    parts = [KINDS[int(rng.integers(len(KINDS)))](rng) for _ in range(int(rng.integers(1, 5)))]
    points, triangles, offset = [], [], 0
    for k, (p, t) in enumerate(parts):
        points.append(p + np.array([k * 50.0, 0, 0]))
        triangles.append(t + offset)
        offset += len(p)
    p, t = np.concatenate(points), np.concatenate(triangles)
    order = rng.permutation(len(p))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(p))
    p, t = p[order], inverse[t]
    t = t[rng.permutation(len(t))]
    roll = rng.integers(0, 3, len(t))
    t = np.stack([t[np.arange(len(t)), (roll + j) % 3] for j in range(3)], 1)
    return p, t.astype(np.int32)


def pinched_surface(seed):
    """2..4 random surfaces glued at vertices (pinched vertices, several fans each): all at one
    vertex (a spider of wings) or in a chain, one vertex per neighbouring pair. Shuffled and
    rotated like random_manifold; the parts overlap in space (the topology is what is tested)."""
    rng = np.random.default_rng(seed)
    parts = [KINDS[int(rng.integers(len(KINDS)))](rng) for _ in range(int(rng.integers(2, 5)))]
    spider = rng.random() < 0.5
    points, triangles, glue, offset = [], [], {}, 0
    anchor = None  # (global id, position) where the next part is glued
    for p, t in parts:
        hub, tail = (int(x) for x in rng.choice(len(p), size=2, replace=False))
        if anchor is not None:
            glue[offset + hub] = anchor[0]
            p = p - p[hub] + anchor[1]
        if anchor is None or not spider:
            end = hub if spider else tail
            anchor = (offset + end, p[end])
        points.append(p)
        triangles.append(t + offset)
        offset += len(p)
    p, t = np.concatenate(points), np.concatenate(triangles)
    ids = np.arange(len(p))
    for source, target in glue.items():
        ids[source] = target
    keep = np.ones(len(p), bool)
    keep[list(glue)] = False
    new_id = np.cumsum(keep) - 1
    t, p = new_id[ids[t]], p[keep]
    order = rng.permutation(len(p))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(p))
    p, t = p[order], inverse[t]
    t = t[rng.permutation(len(t))]
    roll = rng.integers(0, 3, len(t))
    t = np.stack([t[np.arange(len(t)), (roll + j) % 3] for j in range(3)], 1)
    return p, t.astype(np.int32)


# --- the independent check ------------------------------------------------------------------

def drag_case(seed, steps=12, step=0.06):
    """A slider drag over a random surface: (vertices, triangles, ratios, rng). Every third seed
    gives a pinched surface, the others a random manifold; the ratios start in [0.05, 0.5] and
    change by up to ``step`` (relative) each, within [0.02, 0.9]; ``rng`` draws on from there."""
    make = pinched_surface if seed % 3 == 2 else random_manifold
    vertices, triangles = make(seed)
    rng = np.random.default_rng(seed)
    ratio, ratios = rng.uniform(0.05, 0.5), []
    for _ in range(steps):
        ratio = float(np.clip(ratio * (1 + rng.uniform(-step, step)), 0.02, 0.9))
        ratios.append(ratio)
    return vertices, triangles, ratios, rng


def _components(n, a, b):
    """Component label (the smallest member) of each of n nodes joined by edges (a, b): hooking
    and pointer jumping in numpy (scipy's graph set-up costs more than the work on small meshes)."""
    label = np.arange(n)
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    while len(a):
        la, lb = label[a], label[b]
        differ = la != lb
        if not differ.any():
            break
        la, lb = la[differ], lb[differ]
        np.minimum.at(label, np.maximum(la, lb), np.minimum(la, lb))
        while True:
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped
    return label


def _corner_fans(n, t):
    """Fan label of every corner (3 * f + j): corners joined across the edges at their vertex
    that have exactly two triangles."""
    m = len(t)
    tail = np.concatenate([t[:, 0], t[:, 1], t[:, 2]])  # directed edge j*m+f: corner j -> j+1
    head = np.concatenate([t[:, 1], t[:, 2], t[:, 0]])
    _, edge_of, count = np.unique(np.minimum(tail, head) * n + np.maximum(tail, head), return_inverse=True,
                                  return_counts=True)
    edge_of = edge_of.ravel()
    corner_tail = np.concatenate([3 * np.arange(m), 3 * np.arange(m) + 1, 3 * np.arange(m) + 2])
    corner_head = np.concatenate([3 * np.arange(m) + 1, 3 * np.arange(m) + 2, 3 * np.arange(m)])
    order = np.argsort(edge_of, kind="stable")
    two = order[count[edge_of[order]] == 2]
    x, y = two[0::2], two[1::2]
    same = tail[y] == tail[x]
    ja = np.concatenate([corner_tail[x], corner_head[x]])
    jb = np.concatenate([np.where(same, corner_tail[y], corner_head[y]), np.where(same, corner_head[y], corner_tail[y])])
    return _components(3 * m, ja, jb)


def _fans_per_vertex(n, t):
    t = np.asarray(t, dtype=np.int64).reshape(-1, 3)
    m = len(t)
    if m == 0:
        return np.zeros(n, int)
    pairs = np.unique(t.ravel() * (3 * m) + _corner_fans(n, t))
    return np.bincount(pairs // (3 * m), minlength=n)


def surface_facts(n, t):
    """Per vertex its component (-1 if in no triangle), and per component: Euler
    characteristic, boundary loops, manifold and oriented (bool)."""
    t = np.asarray(t, dtype=np.int64).reshape(-1, 3)
    m = len(t)
    used = np.zeros(n, bool)
    used[t.ravel()] = True
    comp = _components(n, np.concatenate([t[:, 0], t[:, 1]]), np.concatenate([t[:, 1], t[:, 2]]))
    labels = np.unique(comp[used])
    comp = np.where(used, np.searchsorted(labels, comp), -1)
    k = len(labels)
    tail = np.concatenate([t[:, 0], t[:, 1], t[:, 2]])  # directed edge j*m+f: corner j -> j+1
    head = np.concatenate([t[:, 1], t[:, 2], t[:, 0]])
    directed_key = tail * n + head
    low, high = np.minimum(tail, head), np.maximum(tail, head)
    keys, edge_of, count = np.unique(low * n + high, return_inverse=True, return_counts=True)
    edge_of = edge_of.ravel()
    edges = np.stack([keys // n, keys % n], 1)
    _, directed_count = np.unique(directed_key, return_counts=True)
    fans_at = _fans_per_vertex(n, t)
    bad_vertex = fans_at > 1
    bad_edge = count > 2
    manifold = np.ones(k, bool)
    manifold[comp[np.flatnonzero(bad_vertex)]] = False
    manifold[comp[edges[bad_edge, 0]]] = False
    oriented = np.ones(k, bool)
    dkeys, dcount = np.unique(directed_key, return_counts=True)
    oriented[comp[dkeys[dcount > 1] // n]] = False
    euler = (np.bincount(comp[used], minlength=k) - np.bincount(comp[edges[:, 0]], minlength=k)
             + np.bincount(comp[t[:, 0]], minlength=k))
    boundary = edges[count == 1]
    loops = np.zeros(k, int)
    if len(boundary):
        bcomp = _components(n, boundary[:, 0], boundary[:, 1])
        on = np.unique(boundary.ravel())
        roots = np.unique(comp[on] * n + bcomp[on])
        loops = np.bincount(roots // n, minlength=k)
    return dict(component=comp, components=k, euler=euler, loops=loops, manifold=manifold, oriented=oriented,
                nonmanifold_edges=int(bad_edge.sum()), nonmanifold_vertices=int(bad_vertex.sum()),
                inconsistent=int((directed_count > 1).sum()))


def flip_patch(n, triangles, seed):
    """The triangles with a patch wound the other way (grown across edges from a random
    triangle to a random share of up to half of them, plus 1 % scattered at random in one mesh
    of two), as the flipped parts of an export; and which triangles were flipped."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    m = len(t)
    rng = np.random.default_rng(seed)
    low, high = np.minimum(t, np.roll(t, -1, axis=1)).ravel(), np.maximum(t, np.roll(t, -1, axis=1)).ravel()
    order = np.argsort(low * n + high, kind="stable")
    key = (low * n + high)[order]
    same = np.flatnonzero(key[1:] == key[:-1])  # pairs of sides on one edge: neighbours
    a, b = order[same] // 3, order[same + 1] // 3
    neighbours = [[] for _ in range(m)]
    for x, y in zip(a.tolist(), b.tolist()):
        neighbours[x].append(y)
        neighbours[y].append(x)
    flip = np.zeros(m, bool)
    size = int(rng.integers(1, max(2, m // 2)))
    frontier = [int(rng.integers(m))]
    flip[frontier[0]] = True
    grown = 1
    while frontier and grown < size:
        f = frontier.pop(0)
        for g in neighbours[f]:
            if not flip[g] and grown < size:
                flip[g] = True
                grown += 1
                frontier.append(g)
    if rng.random() < 0.5:
        flip |= rng.random(m) < 0.01
    out = t.copy()
    out[flip] = out[flip][:, ::-1]
    return out.astype(np.int32), flip


def check_windings(n, triangles, out_triangles, kept):
    """Violations of the windings a decimation of a manifold input with flipped triangles must
    keep: each output component consistently oriented exactly where its input component is.
    (Wound back by their sources' flips, the output triangles must be consistently oriented:
    check_decimation checks that with unflipped.)"""
    problems = []
    ot = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
    if not len(ot):
        return problems
    before, after = surface_facts(n, triangles), surface_facts(len(kept), ot)
    in_comp = before["component"][np.asarray(kept)]
    for c in range(after["components"]):
        members = np.unique(in_comp[after["component"] == c])
        if len(members) == 1 and after["oriented"][c] != before["oriented"][members[0]]:
            problems.append(f"component {int(members[0])}: consistently oriented "
                            f"{bool(before['oriented'][members[0]])} -> {bool(after['oriented'][c])}")
    return problems


def unflipped(n, triangles, flip, out_triangles, face_source):
    """The output with each triangle whose source was flipped wound back: consistently oriented
    where the decimation is right. Where a component's flipped patches or all its unflipped
    triangles went, the engine turns that component's first output triangle so that it stays
    inconsistently oriented (decimate.hpp's restore_winding): that one is wound back too."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    flip = np.asarray(flip, bool)
    ot = np.array(out_triangles, dtype=np.int64).reshape(-1, 3)
    source = np.asarray(face_source, dtype=np.int64)
    back = flip[source].copy()
    component = surface_facts(n, t)["component"][t[:, 0]]  # per input triangle
    for c in np.unique(component):
        mine = component[source] == c
        if flip[component == c].any() and not flip[component == c].all() and mine.any():
            if flip[source[mine]].all() or not flip[source[mine]].any():
                back[np.flatnonzero(mine)[0]] ^= True
    ot[back] = ot[back][:, ::-1]
    return ot


def check_decimation(vertices, triangles, out_vertices, out_triangles, kept, before=None):
    """Violations of the guarantees by a decimation of a manifold input, as a list of strings
    (empty when every guarantee holds). before: surface_facts of the input, if known."""
    problems = []
    n = len(vertices)
    if before is None:
        before = surface_facts(n, triangles)
    ot = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
    if not np.isfinite(out_vertices).all():
        problems.append("non-finite coordinates")
    if len(ot) and ((ot[:, 0] == ot[:, 1]) | (ot[:, 1] == ot[:, 2]) | (ot[:, 2] == ot[:, 0])).any():
        return problems + ["triangle with a repeated corner"]
    st = np.sort(ot, axis=1)
    nn = max(1, len(out_vertices))
    if len(np.unique((st[:, 0] * nn + st[:, 1]) * nn + st[:, 2])) != len(ot):
        problems.append("duplicate triangles")
    after = surface_facts(len(out_vertices), ot)
    if after["nonmanifold_edges"] or after["nonmanifold_vertices"]:
        problems.append(f"non-manifold output ({after['nonmanifold_edges']} edges, "
                        f"{after['nonmanifold_vertices']} vertices)")
    if after["inconsistent"]:
        problems.append(f"{after['inconsistent']} inconsistently oriented edges")
    # map output components to input components through kept vertices
    in_comp_of_out = before["component"][np.asarray(kept)]
    if after["components"] != before["components"]:
        problems.append(f"{before['components']} components became {after['components']}")
        return problems
    mapping = {}
    for c in range(after["components"]):
        members = np.unique(in_comp_of_out[after["component"] == c])
        if len(members) != 1 or int(members[0]) in mapping.values():
            problems.append("output components do not match the input's")
            return problems
        mapping[c] = int(members[0])
    for c, ci in mapping.items():
        if after["euler"][c] != before["euler"][ci]:
            problems.append(f"component {ci}: Euler characteristic {before['euler'][ci]} -> {after['euler'][c]}")
        if after["loops"][c] != before["loops"][ci]:
            problems.append(f"component {ci}: boundary loops {before['loops'][ci]} -> {after['loops'][c]}")
    return problems


def unpinch(n, t):
    """Splits every vertex with several fans into one vertex per fan (the first fan keeps the
    id, the others get new ids from n on). Returns the new triangles and the original vertex
    of every vertex of the result."""
    t = np.asarray(t, dtype=np.int64).reshape(-1, 3)
    m = len(t)
    if m == 0:
        return t, np.arange(n)
    fans = _corner_fans(n, t)
    corner_vertex = t.ravel()
    key = corner_vertex * (3 * m) + fans  # one key per (vertex, fan)
    keys, fan_index = np.unique(key, return_inverse=True)
    key_vertex = keys // (3 * m)
    first = np.ones(len(keys), bool)
    first[1:] = key_vertex[1:] != key_vertex[:-1]
    new_id = np.where(first, key_vertex, n + np.cumsum(~first) - 1)
    origin = np.concatenate([np.arange(n), key_vertex[~first]])
    return new_id[fan_index.ravel()].reshape(-1, 3), origin


def check_pinched_decimation(vertices, triangles, out_vertices, out_triangles, kept):
    """Violations by a decimation of a surface that is manifold but for pinched vertices: each
    pinched input vertex must be kept, and splitting every pinched vertex of the input and of
    the output into one vertex per fan must give a decimation that check_decimation accepts
    (the same wings, each homeomorphic to its input, nothing lost or merged)."""
    n = len(vertices)
    facts = surface_facts(n, triangles)
    kept = np.asarray(kept)
    fans_at = _fans_per_vertex(n, triangles)
    missing = np.setdiff1d(np.flatnonzero(fans_at > 1), kept)
    problems = [f"pinched input vertices not kept: {missing.tolist()}"] if len(missing) else []
    ot = np.asarray(out_triangles, dtype=np.int64).reshape(-1, 3)
    if len(ot) and ((ot[:, 0] == ot[:, 1]) | (ot[:, 1] == ot[:, 2]) | (ot[:, 2] == ot[:, 0])).any():
        return problems + ["triangle with a repeated corner"]
    split_in, origin_in = unpinch(n, triangles)
    split_out, origin_out = unpinch(len(out_vertices), ot)
    # Each output fan copy maps to the input copy of its vertex on the wing its triangles' other
    # corners come from (their own input copies, where they have one).
    in_facts = surface_facts(len(origin_in), split_in)
    copies = {}
    for c, v in enumerate(origin_in):
        copies.setdefault(int(v), []).append(c)
    split_kept = np.array([copies[int(kept[v])][0] for v in origin_out])
    for j in np.flatnonzero(np.array([len(copies[int(kept[v])]) > 1 for v in origin_out])):
        wings = [in_facts["component"][split_kept[x]] for tri in split_out[(split_out == j).any(1)]
                 for x in tri if x != j and len(copies[int(kept[origin_out[x]])]) == 1]
        candidates = copies[int(kept[origin_out[j]])]
        match = [c for c in candidates if wings and in_facts["component"][c] == max(set(wings), key=wings.count)]
        split_kept[j] = match[0] if match else candidates[0]
    return problems + check_decimation(np.asarray(vertices)[origin_in], split_in,
                                       np.asarray(out_vertices)[origin_out], split_out, split_kept, in_facts)
