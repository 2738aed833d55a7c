"""Topology editing (issue 6): delete faces, cut along a loop, fill holes, remove a handle.

Checked against independent numpy code (tests/reference.py for invariants; brute force here
for maps, areas and overlaps) and, when built, CGAL's self-intersection test (build/peers).
"""

import pathlib
import subprocess

import numpy as np
import pytest

import meshgen
import reference as ref
from topstoc.core.api import edit

ROOT = pathlib.Path(__file__).resolve().parents[2]
CGAL_EDIT = ROOT / "build" / "peers" / "cgal_edit"


# --- helpers (independent of topstoc) ----------------------------------------------------------

def read_off(path):
    """OFF reader: polygons fan-triangulated, vertex order kept."""
    tokens = [t for line in pathlib.Path(path).read_text().splitlines() for t in line.split("#")[0].split()]
    assert tokens[0] == "OFF"
    nv, nf = int(tokens[1]), int(tokens[2])
    at = 4
    vertices = np.array(tokens[at:at + 3 * nv], dtype=float).reshape(nv, 3)
    at += 3 * nv
    triangles = []
    for _ in range(nf):
        k = int(tokens[at])
        ids = [int(x) for x in tokens[at + 1:at + 1 + k]]
        at += 1 + k
        triangles += [(ids[0], ids[j], ids[j + 1]) for j in range(1, k - 1)]
    return vertices, np.array(triangles, dtype=np.int32)


def write_off(path, vertices, triangles):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(vertices)} {len(triangles)} 0\n")
        np.savetxt(f, vertices, fmt="%.17g")
        np.savetxt(f, np.c_[np.full(len(triangles), 3), triangles], fmt="%d")


def summary(vertices, triangles):
    """(components, boundary loops, manifold, orientable, genus list) by the reference code."""
    inv = ref.invariants(len(vertices), triangles)
    genus = [ref.euler_genus(chi, b) for chi, b, _, _ in inv]
    return len(inv), sum(b for _, b, _, _ in inv), all(m for _, _, m, _ in inv), all(o for *_, o in inv), genus


def areas(vertices, triangles):
    t = np.asarray(triangles)
    return 0.5 * np.linalg.norm(np.cross(vertices[t[:, 1]] - vertices[t[:, 0]], vertices[t[:, 2]] - vertices[t[:, 0]]),
                                axis=1)


def directed_edges_unique(triangles):
    """Every directed edge at most once: consistently oriented, no edge in 3+ triangles."""
    t = np.asarray(triangles, dtype=np.int64)
    he = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    return len(np.unique(he, axis=0)) == len(he)


def boundary_edges(triangles):
    e, counts = np.unique(ref.undirected_edges(triangles), axis=0, return_counts=True)
    return {tuple(x) for x in e[counts == 1]}


def closed_surface_summary(triangles):
    """(components, Euler characteristic) of a closed, consistently oriented, manifold surface,
    asserting that it is one: numpy only, fast enough to run after every edit.

    Every directed edge appears once and its reverse once (closed, edge-manifold, oriented);
    around every vertex the triangles form one cycle (counted as the cycles of the corner
    rotation permutation by pointer doubling); components by label propagation.
    """
    t = np.asarray(triangles, dtype=np.int64)
    m = len(t)
    tails = t.reshape(-1)                      # corner (f, c) sits at vertex t[f, c]
    heads = t[:, [1, 2, 0]].reshape(-1)        # the half-edge leaving that corner
    n = int(t.max()) + 1
    keys = tails * n + heads
    order = np.argsort(keys)
    assert np.all(np.diff(keys[order]) > 0), "a directed edge appears twice"
    twins = np.searchsorted(keys[order], heads * n + tails)
    assert np.all(twins < len(keys)) and np.all(keys[order][np.minimum(twins, len(keys) - 1)] == heads * n + tails), \
        "an edge has no opposite half-edge (boundary or inconsistent orientation)"
    # Rotation around the vertex of corner (f, c): the corner of the same vertex in the triangle
    # holding the half-edge from it to t[f, c + 2].
    previous = t[:, [2, 0, 1]].reshape(-1)
    rotation = order[np.searchsorted(keys[order], tails * n + previous)]
    label, step = np.arange(3 * m), rotation.copy()
    for _ in range(int(np.ceil(np.log2(3 * m + 1))) + 1):
        label = np.minimum(label, label[step])
        step = step[step]
    fans = np.count_nonzero(label == np.arange(3 * m))
    used = np.unique(tails)
    assert fans == len(used), f"{fans - len(used)} pinched vertices"
    # Components: propagate the smallest vertex id along edges (every edge is in both
    # directions, so pulling from heads suffices) with pointer jumping, until nothing changes.
    by_tail = np.argsort(tails, kind="stable")
    starts = np.searchsorted(tails[by_tail], used)
    comp = np.arange(n)
    while True:
        new = comp.copy()
        new[used] = np.minimum(comp[used], np.minimum.reduceat(comp[heads[by_tail]], starts))
        new = new[new]
        if np.array_equal(new, comp):
            break
        comp = new
    edges = 3 * m // 2
    return len(np.unique(comp[used])), len(used) - edges + m


def generator_loop(vertices, triangles):
    """A shortest non-separating cycle among the tree-cotree generators (Eppstein 2003).

    BFS tree T on vertices from a vertex of triangle 0, BFS tree C on faces across edges not in
    T; every edge in neither closes a loop with T that is non-trivial in homology, hence
    non-separating. Returns the vertex cycle (tree path u .. lca .. v), or None for genus 0.
    """
    t = np.asarray(triangles, dtype=np.int64)
    sides = np.sort(np.stack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]], axis=1).reshape(-1, 2), axis=1)
    edges, edge_of_side = np.unique(sides, axis=0, return_inverse=True)
    edge_of_side = edge_of_side.reshape(-1)
    n = len(vertices)
    # Vertex adjacency (CSR) with the edge id of each slot.
    ends = np.concatenate([edges[:, 0], edges[:, 1]])
    others = np.concatenate([edges[:, 1], edges[:, 0]])
    ids = np.concatenate([np.arange(len(edges))] * 2)
    order = np.lexsort((others, ends))
    ends, others, ids = ends[order], others[order], ids[order]
    start = np.searchsorted(ends, np.arange(n + 1))
    root = int(t[0, 0])
    parent, depth, in_tree = [-1] * n, [0] * n, [False] * len(edges)
    parent[root] = root
    others_list, ids_list, start_list = others.tolist(), ids.tolist(), start.tolist()
    queue = [root]
    for u in queue:
        for slot in range(start_list[u], start_list[u + 1]):
            v = others_list[slot]
            if parent[v] < 0:
                parent[v], depth[v], in_tree[ids_list[slot]] = u, depth[u] + 1, True
                queue.append(v)
    # The two faces of every edge (closed surface), then BFS over faces across non-tree edges.
    faces_of_edge = np.argsort(edge_of_side, kind="stable").reshape(-1, 2) // 3
    in_cotree, seen = [False] * len(edges), [False] * len(t)
    seen[0] = True
    queue = [0]
    side_edges, face_pairs = edge_of_side.tolist(), faces_of_edge.tolist()
    for f in queue:
        for e in side_edges[3 * f:3 * f + 3]:
            if in_tree[e] or in_cotree[e]:
                continue
            a, b = face_pairs[e]
            g = a if b == f else b
            if not seen[g]:
                seen[g] = True
                in_cotree[e] = True
                queue.append(g)
    best = None
    for e in np.flatnonzero(~np.array(in_tree) & ~np.array(in_cotree)):
        left, right = [int(edges[e, 0])], [int(edges[e, 1])]
        while left[-1] != right[-1]:
            if depth[left[-1]] >= depth[right[-1]]:
                left.append(parent[left[-1]])
            else:
                right.append(parent[right[-1]])
        cycle = left + right[-2::-1]
        if best is None or len(cycle) < len(best):
            best = cycle
    return best


def cgal_new_intersections(tmp_path, vertices, triangles, first_new):
    """Pairs of intersecting triangles that involve a triangle >= first_new (CGAL), or None."""
    if not CGAL_EDIT.exists():
        return None
    path = tmp_path / "mesh.off"
    write_off(path, vertices, triangles)
    out = subprocess.run([str(CGAL_EDIT), "self-intersections", str(path)], capture_output=True, text=True, check=True)
    pairs = [tuple(map(int, line.split())) for line in out.stdout.splitlines() if line and not line.startswith("pairs")]
    return [p for p in pairs if max(p) >= first_new]


def mobius(n=12):
    """A Moebius band: n x 2 strip glued with a half twist; the centre loop is one-sided."""
    vertices = []
    for i in range(n):
        t = 2 * np.pi * i / n
        for s in (-1, 0, 1):
            w = 0.3 * s
            vertices.append(((1 + w * np.cos(t / 2)) * np.cos(t), (1 + w * np.cos(t / 2)) * np.sin(t), w * np.sin(t / 2)))
    idx = lambda i, s: 3 * (i % n) + s  # noqa: E731
    triangles = []
    for i in range(n):
        for s in range(2):
            a, b = idx(i, s), idx(i, s + 1)
            c, d = (idx(0, 1 - s), idx(0, 2 - s)) if i == n - 1 else (idx(i + 1, s + 1), idx(i + 1, s))
            triangles += [(a, d, c), (a, c, b)]
    return np.array(vertices), np.array(triangles, dtype=np.int32), [idx(i, 1) for i in range(n)]


def height_field(n, height, hole_radius):
    """Grid over [-1, 1]^2 lifted by z = height(x, y), with the triangles whose centroid lies within
    hole_radius of the centre removed: a hole whose border follows the surface."""
    vertices, triangles = meshgen.grid(n, n)
    vertices = vertices / n * 2 - np.array([1, 1, 0])
    vertices[:, 2] = height(vertices[:, 0], vertices[:, 1])
    centroids = vertices[triangles].mean(axis=1)
    keep = np.hypot(centroids[:, 0], centroids[:, 1]) > hole_radius
    return vertices, triangles[keep]


def polygon_area_xy(points):
    x, y = points[:, 0], points[:, 1]
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def genus_meshes():
    return sorted((pathlib.Path(__file__).parents[1] / "data" / "genus_positive").glob("*.off"))


# --- delete ----------------------------------------------------------------------------------------

def test_delete_faces_maps_and_drops_only_newly_isolated_vertices():
    vertices, triangles = meshgen.torus(12, 8)
    vertices = np.vstack([vertices, [[9.0, 9.0, 9.0]]])  # an already isolated vertex: stays
    rng = np.random.default_rng(1)
    doomed = rng.choice(len(triangles), 60, replace=False)
    before_v, before_t = vertices.copy(), triangles.copy()
    result = edit.delete_faces(vertices, triangles, np.r_[doomed, doomed[:5]])  # repeats allowed
    assert np.array_equal(vertices, before_v) and np.array_equal(triangles, before_t)

    kept = np.setdiff1d(np.arange(len(triangles)), doomed)
    used_after = np.zeros(len(vertices), bool)
    used_after[triangles[kept].ravel()] = True
    used_before = np.zeros(len(vertices), bool)
    used_before[triangles.ravel()] = True
    expected_vertices = np.flatnonzero(used_after | ~used_before)
    assert np.array_equal(result.vertex_source, expected_vertices)
    assert np.array_equal(result.face_source, kept)
    assert np.array_equal(result.vertex_source[result.triangles], triangles[kept])  # same corners, same order
    assert np.array_equal(result.vertices, vertices[expected_vertices])
    assert np.array_equal(result.corner_source, 3 * kept[:, None] + np.arange(3))
    old_to_new = result.vertex_map()
    assert np.all(old_to_new[~(used_after | ~used_before)] == -1)
    assert np.array_equal(old_to_new[expected_vertices], np.arange(len(expected_vertices)))
    assert np.array_equal(result.face_map()[kept], np.arange(len(kept)))

    mask = np.zeros(len(triangles), bool)
    mask[doomed] = True
    by_mask = edit.delete_faces(vertices, triangles, mask)
    assert np.array_equal(by_mask.triangles, result.triangles)


def test_delete_faces_accepts_degenerate_triangles_and_rejects_bad_indices():
    vertices, triangles = meshgen.grid(2, 2)
    triangles = np.vstack([triangles, [[0, 0, 1]]])
    result = edit.delete_faces(vertices, triangles, [len(triangles) - 1])
    assert result.num_triangles == len(triangles) - 1
    with pytest.raises(ValueError, match="face entry 0 is triangle 99"):
        edit.delete_faces(vertices, triangles, [99])
    with pytest.raises(ValueError, match="mask"):
        edit.delete_faces(vertices, triangles, np.ones(3, bool))


# --- cut -------------------------------------------------------------------------------------------

def test_cut_torus_meridian_opens_a_cylinder():
    vertices, triangles = meshgen.torus(16, 8)
    loop = np.arange(8)  # the meridian at u = 0
    result = edit.cut_along_loop(vertices, triangles, loop)
    assert summary(result.vertices, result.triangles) == (1, 2, True, True, [0])
    assert result.num_vertices == len(vertices) + len(loop)
    assert np.array_equal(result.vertices[:len(vertices)], vertices)  # ids and positions kept
    assert np.array_equal(result.vertices, vertices[result.vertex_source])
    assert np.array_equal(result.vertex_source[len(vertices):], loop)
    assert np.array_equal(result.vertex_source[result.triangles], triangles)  # corner order kept
    assert directed_edges_unique(result.triangles)
    # The two sides are exactly the new boundary, each a copy of the loop, surface on the left.
    assert [len(side.vertices) for side in result.cut_sides] == [8, 8]
    assert all(side.closed for side in result.cut_sides)
    side_edges = set()
    for side in result.cut_sides:
        assert sorted(result.vertex_source[side.vertices]) == sorted(loop)
        for a, b in zip(side.vertices, np.roll(side.vertices, -1)):
            side_edges.add((min(a, b), max(a, b)))
            # a triangle runs a -> b along the side
            assert any(tuple(t[[i, (i + 1) % 3]]) == (a, b) for t in result.triangles for i in range(3))
    assert side_edges == boundary_edges(result.triangles)


def test_cut_separating_loop_on_a_disk_and_a_loop_touching_the_boundary():
    vertices, triangles = meshgen.grid(4, 4)  # vertex (i, j) has id 5 i + j
    inner = [6, 7, 8, 13, 18, 17, 16, 11]  # around vertex (2, 2)
    result = edit.cut_along_loop(vertices, triangles, inner)
    assert summary(result.vertices, result.triangles)[:2] == (2, 3)  # a disk and an annulus
    touching = [2, 8, 13, 12, 11, 6, 7]  # passes through boundary vertex (0, 2)
    result = edit.cut_along_loop(vertices, triangles, touching)
    comps, loops, manifold, orientable, _ = summary(result.vertices, result.triangles)
    assert (comps, loops, manifold, orientable) == (2, 2, True, True)
    assert sorted(side.closed for side in result.cut_sides) == [False, True]
    assert (result.vertex_source == 2).sum() == 3  # one copy per sector at the boundary vertex


def test_cut_one_sided_loop_of_a_moebius_band():
    vertices, triangles, centre = mobius()
    assert ref.invariants(len(vertices), triangles) == [(0, 1, True, False)]
    result = edit.cut_along_loop(vertices, triangles, centre)
    assert len(result.cut_sides) == 1 and len(result.cut_sides[0].vertices) == 2 * len(centre)
    assert ref.invariants(result.num_vertices, result.triangles) == [(0, 2, True, True)]  # an annulus


@pytest.mark.parametrize("loop, message", [
    ([0, 1], "at least 3"),
    ([0, 1, 2, 1], "visits vertex 1 twice"),
    ([0, 1, 17], "not joined by an edge"),
    ([0, 1, 99999], "outside"),
])
def test_cut_rejects_non_cycles(loop, message):
    vertices, triangles = meshgen.torus(16, 8)
    with pytest.raises(ValueError, match=message):
        edit.cut_along_loop(vertices, triangles, loop)


def test_cut_rejects_boundary_edges_and_non_manifold_vertices():
    vertices, triangles = meshgen.grid(3, 3)
    with pytest.raises(ValueError, match="lies on the mesh boundary"):
        edit.cut_along_loop(vertices, triangles, [0, 1, 5])
    # Two tori glued at one vertex: the shared vertex is pinched (two fans).
    v1, t1 = meshgen.torus(8, 6)
    v2, t2 = meshgen.torus(8, 6)
    v2 = v2 + [5, 0, 0]
    t2 = np.where(t2 == 0, 0, t2 + len(v1))
    vertices, triangles = np.vstack([v1, v2]), np.vstack([t1, t2]).astype(np.int32)
    with pytest.raises(ValueError, match="non-manifold"):
        edit.cut_along_loop(vertices, triangles, np.arange(6))


# --- boundary loops and filling ---------------------------------------------------------------------

def test_boundary_loops_match_reference_and_run_with_the_surface_on_the_left():
    vertices, triangles = meshgen.disjoint(meshgen.grid(3, 3), meshgen.grid(2, 5))
    loops = edit.boundary_loops(vertices, triangles)
    assert len(loops) == 2 and all(loop.fillable for loop in loops)
    expected = boundary_edges(triangles)
    got = {(min(a, b), max(a, b)) for loop in loops for a, b in zip(loop.vertices, np.roll(loop.vertices, -1))}
    assert got == expected
    directed = {tuple(t[[i, (i + 1) % 3]]) for t in triangles for i in range(3)}
    for loop in loops:
        assert loop.vertices[0] == loop.vertices.min()
        assert all((a, b) in directed for a, b in zip(loop.vertices, np.roll(loop.vertices, -1)))


def test_fill_flat_holes_exactly_covers_them():
    """Non-convex holes in a flat grid, with collinear border vertices: the patch lies in the
    plane, every triangle turns the same way and the patch area is the deleted area."""
    vertices, triangles = meshgen.grid(14, 14)
    x, y = vertices[:, 0], vertices[:, 1]
    l_shape = (x > 2) & (x < 6) & (y > 2) & (y < 10) & ~((x > 4) & (y > 4))
    star = np.hypot(x - 9.5, y - 8.5) < 2.5 + 1.2 * np.cos(5 * np.arctan2(y - 8.5, x - 9.5))
    doomed = np.flatnonzero((l_shape | star)[triangles].any(axis=1))
    holed = edit.delete_faces(vertices, triangles, doomed)
    loops = edit.boundary_loops(holed.vertices, holed.triangles)
    inner = [i for i, loop in enumerate(loops) if 0 not in loop.vertices]  # vertex 0 is on the border
    result = edit.fill_holes(holed.vertices, holed.triangles, holes=inner)
    assert summary(result.vertices, result.triangles)[:4] == (1, 1, True, True)
    assert len(result.patches) == 2 and {p.method for p in result.patches} == {"planar"}
    patch_rows = np.concatenate([np.arange(p.triangles.start, p.triangles.stop) for p in result.patches])
    patch = result.triangles[patch_rows]
    assert np.allclose(result.vertices[:, 2], 0)
    a, b, c = (result.vertices[patch[:, i], :2] for i in range(3))
    signed = 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    assert np.all(signed > 1e-9)  # same orientation as the grid, none degenerate
    assert np.isclose(signed.sum(), areas(vertices, triangles[doomed]).sum())
    assert directed_edges_unique(result.triangles)


def test_fill_elephant_and_mushroom(data_dir, tmp_path):
    for name, genus in (("cgal_elephant-with-holes.off", 3), ("cgal_mushroom.off", 0)):
        vertices, triangles = read_off(data_dir / "open_boundary" / name)
        result = edit.fill_holes(vertices, triangles)
        assert summary(result.vertices, result.triangles) == (1, 0, True, True, [genus]), name
        assert directed_edges_unique(result.triangles)
        assert np.all(areas(result.vertices, result.triangles) > 0)
        # Kept vertices keep their positions; welded duplicates sat exactly where their target is.
        assert np.array_equal(result.vertices[result.vertex_source >= 0],
                              vertices[result.vertex_source[result.vertex_source >= 0]])
        # Input triangles come first, in order, their corners at the same positions (a welded
        # duplicate's corner now uses its twin, which sits at exactly the same place).
        assert np.array_equal(result.face_source[:len(triangles)], np.arange(len(triangles)))
        assert np.array_equal(result.vertices[result.triangles[:len(triangles)]], vertices[triangles])
        for patch in result.patches:
            tri = result.triangles[patch.triangles]
            normals = np.cross(result.vertices[tri[:, 1]] - result.vertices[tri[:, 0]],
                               result.vertices[tri[:, 2]] - result.vertices[tri[:, 0]])
            assert np.all(np.linalg.norm(normals, axis=1) > 0)
            if patch.method == "planar":  # a height field over its plane: nothing flipped
                assert np.all(normals @ patch.normal > 0), (name, patch.hole)
        pairs = cgal_new_intersections(tmp_path, result.vertices, result.triangles, len(triangles))
        if pairs is not None:
            assert pairs == [], f"{name}: patches intersect the surface or each other: {pairs[:5]}"


def test_fill_elephant_patch_methods_and_welds(data_dir):
    vertices, triangles = read_off(data_dir / "open_boundary" / "cgal_elephant-with-holes.off")
    loops = edit.boundary_loops(vertices, triangles)
    assert len(loops) == 106
    pinched = [i for i, loop in enumerate(loops)
               if len(np.unique(vertices[loop.vertices], axis=0)) < len(loop)]
    result = edit.fill_holes(vertices, triangles)
    # Every welded vertex had a twin at the same position on the same loop.
    removed = np.setdiff1d(np.arange(len(vertices)), result.vertex_source)
    assert len(removed) == len(vertices) - result.num_vertices > 0
    assert {p.hole for p in result.patches} == set(range(106))
    patches_per_hole = np.bincount([p.hole for p in result.patches])
    assert set(np.flatnonzero(patches_per_hole > 1)) <= set(pinched)  # lobes only where welded
    assert len(pinched) > 0
    planar = sum(p.method == "planar" for p in result.patches)
    assert planar >= 0.95 * len(result.patches)
    unwelded = edit.fill_holes(vertices, triangles, weld_pinches=False)
    assert unwelded.num_vertices == len(vertices) and len(unwelded.patches) == 106
    assert summary(unwelded.vertices, unwelded.triangles) == (1, 0, True, True, [3])


def test_fill_saddles_without_overlap():
    """Saddle-shaped (non-planar) holes, tall and flat, by the planar method and by the 3D
    fallback alone: the patch is a graph over the xy plane (projected areas all positive and
    summing to the hole's projected area), so it cannot overlap itself."""
    for amplitude in (0.3, 2.0):
        vertices, triangles = height_field(16, lambda x, y: amplitude * (x * x - y * y), 0.55)
        loops = edit.boundary_loops(vertices, triangles)
        index = min(range(len(loops)), key=lambda i: len(loops[i]))
        hole = loops[index]
        z = vertices[hole.vertices, 2]
        assert z.max() - z.min() > 0.2 * amplitude  # really not planar
        for planar in (True, False):
            result = edit.fill_holes(vertices, triangles, holes=[index], planar=planar)
            (patch,) = result.patches
            tri = result.triangles[patch.triangles]
            a, b, c = (result.vertices[tri[:, i], :2] for i in range(3))
            signed = 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
            hole_area = abs(polygon_area_xy(result.vertices[patch.boundary]))
            assert patch.method == ("planar" if planar else "minimum_weight")
            assert np.all(signed > 0), (amplitude, planar)
            assert np.isclose(signed.sum(), hole_area)
            assert summary(result.vertices, result.triangles)[:4] == (1, 1, True, True)


def test_fill_3d_fallback_on_a_wrapping_window(tmp_path):
    """A window wrapping 300 degrees round a tube, filled by the 3D fallback alone: minimum
    weight, and split once or several times. Always manifold and non-degenerate; the minimum
    weight patch and a single split cut no triangle (CGAL, when built). Deep splits may: their
    pieces are filled independently (a known limit of the last-resort path)."""
    vertices, triangles = meshgen.torus(48, 24, major=3.0, minor=0.5)
    u = np.arctan2(vertices[:, 1], vertices[:, 0])
    v = np.arctan2(vertices[:, 2], np.hypot(vertices[:, 0], vertices[:, 1]) - 3.0)
    # Thresholds halfway between grid angles (u: 7.5 degree steps, v: 15): a threshold on a grid
    # angle made the window depend on the last bit of arctan2 (NumPy 1.24 and 2.x disagreed).
    inside = (np.abs(u) < 0.5) & (np.abs(v) < np.radians(142.5))
    doomed = np.flatnonzero(inside[triangles].all(axis=1))
    holed = edit.delete_faces(vertices, triangles, doomed)
    (hole,) = edit.boundary_loops(holed.vertices, holed.triangles)
    assert len(hole) == 48
    for max_dp_corners, method, clean in ((300, "minimum_weight", True), (30, "split", True), (12, "split", False)):
        result = edit.fill_holes(holed.vertices, holed.triangles, planar=False, max_dp_corners=max_dp_corners)
        (patch,) = result.patches
        assert patch.method == method
        assert summary(result.vertices, result.triangles) == (1, 0, True, True, [1])
        assert np.all(areas(result.vertices, result.triangles) > 0)
        pairs = cgal_new_intersections(tmp_path, result.vertices, result.triangles, holed.num_triangles)
        if pairs is not None and clean:
            assert pairs == [], max_dp_corners


def test_fill_never_reuses_an_existing_edge():
    # Two triangles sharing diagonal 0-2 form a square; its other side is a hole whose only
    # valid triangulation uses the other diagonal (a flat pillow, closed and manifold).
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    triangles = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    result = edit.fill_holes(vertices, triangles)
    assert ref.invariants(4, result.triangles) == [(2, 0, True, True)]
    assert {frozenset(t) for t in result.triangles[2:]} == {frozenset((0, 1, 3)), frozenset((1, 2, 3))}


def test_fill_selection_and_size_limit():
    vertices, triangles = meshgen.grid(10, 10)
    centroids = vertices[triangles].mean(axis=1)
    small = np.hypot(centroids[:, 0] - 2.5, centroids[:, 1] - 2.5) < 0.8
    big = np.hypot(centroids[:, 0] - 6.5, centroids[:, 1] - 6.5) < 2.2
    holed = edit.delete_faces(vertices, triangles, np.flatnonzero(small | big))
    loops = edit.boundary_loops(holed.vertices, holed.triangles)
    sizes = sorted(len(loop) for loop in loops)
    assert len(loops) == 3  # the outer border and two holes
    only_small = edit.fill_holes(holed.vertices, holed.triangles, max_edges=sizes[0])
    assert [len(p.boundary) for p in only_small.patches] == [sizes[0]]
    chosen = edit.fill_holes(holed.vertices, holed.triangles, holes=[1, 2])
    assert [p.hole for p in chosen.patches] == [1, 2]
    with pytest.raises(ValueError, match="hole index 7 is out of range"):
        edit.fill_holes(holed.vertices, holed.triangles, holes=[7])


def test_fill_rejects_bad_holes():
    # Two squares touching at one corner: that vertex is on two boundary loops.
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 1, 0], [2, 2, 0], [1, 2, 0.0]])
    triangles = np.array([[0, 1, 2], [0, 2, 3], [2, 4, 5], [2, 5, 6]], dtype=np.int32)
    loops = edit.boundary_loops(vertices, triangles)
    assert all(loop.nonmanifold_vertex == 2 for loop in loops)
    with pytest.raises(ValueError, match="non-manifold vertex 2"):
        edit.fill_holes(vertices, triangles)
    assert edit.fill_holes(vertices, triangles, skip_unfillable=True).patches == []
    with pytest.raises(ValueError, match="non-manifold vertex 2"):
        edit.fill_loops(vertices, triangles, [[0, 1, 2, 3]])
    with pytest.raises(ValueError, match="lone triangle"):
        edit.fill_holes(vertices[:3], triangles[:1])
    with pytest.raises(ValueError, match="lone triangle"):
        edit.fill_loops(vertices[:3], triangles[:1], [[0, 1, 2]])
    lone = edit.boundary_loops(*meshgen.disjoint(meshgen.grid(1, 1), (vertices[:3], triangles[:1])))
    assert [loop.lone_triangle for loop in lone] == [False, True] and not lone[1].fillable
    assert len(edit.fill_holes(*meshgen.disjoint(meshgen.grid(1, 1), (vertices[:3], triangles[:1])),
                               skip_unfillable=True).patches) == 1
    grid_v, grid_t = meshgen.grid(3, 3)
    with pytest.raises(ValueError, match="not joined by a boundary edge"):
        edit.fill_loops(grid_v, grid_t, [[5, 6, 10, 9]])  # an interior cycle
    with pytest.raises(ValueError, match="twice"):
        edit.fill_loops(grid_v, grid_t, [[0, 1, 2, 1]])
    nan = grid_v.copy()
    nan[0, 0] = np.nan
    with pytest.raises(ValueError, match="vertex 0 has a non-finite coordinate"):
        edit.fill_holes(nan, grid_t)
    with pytest.raises(ValueError, match="repeats a vertex"):
        edit.fill_holes(grid_v, np.vstack([grid_t, [[1, 1, 2]]]).astype(np.int32))


def test_refine_and_fair_patch():
    vertices, triangles = height_field(20, lambda x, y: 0.5 * (x * x + y * y), 0.5)  # a hole in a bowl
    hole = min(range(2), key=lambda i: len(edit.boundary_loops(vertices, triangles)[i]))
    flat = edit.fill_holes(vertices, triangles, holes=[hole])
    fair = edit.fill_holes(vertices, triangles, holes=[hole], fair=True)
    (patch,) = fair.patches
    added = fair.vertices[patch.vertices]
    assert len(added) > 10 and np.all(fair.vertex_source[patch.vertices] == -1)
    assert summary(fair.vertices, fair.triangles)[:4] == (1, 1, True, True)
    # Edges of the refined patch are about as long as the grid's (0.1) instead of spanning the hole.
    tri = fair.triangles[patch.triangles]
    lengths = np.linalg.norm(fair.vertices[tri] - fair.vertices[np.roll(tri, 1, axis=1)], axis=2)
    assert lengths.mean() < 0.2
    # Fairing bends the patch down into the bowl (z = 0.5 r^2 continues below the rim).
    rim = vertices[flat.patches[0].boundary, 2].mean()
    assert added[:, 2].min() < rim - 0.02 and np.all(added[:, 2] > -0.05)
    colours = np.random.default_rng(0).random((len(vertices), 3))
    carried = fair.vertex_attribute(colours)
    assert np.allclose(carried[patch.vertices], colours[fair.vertex_source[patch.boundary]].mean(axis=0))



def test_fair_lifts_a_sliver_patch_off_its_plane():
    """A triangular hole that is a sliver: its flat patch is the hole's own triangle (aspect
    6.7), which no flat refinement improves; the faired patch lifts a centre vertex off it, to
    the sphere's outside (where fairing bends it), low enough that every triangle is within
    aspect 5. A well-shaped triangular hole keeps its one triangle."""
    vertices, triangles = meshgen.icosphere(3)
    a, b, c = triangles[0]
    middle = 0.5 * (vertices[a] + vertices[b])
    vertices[c] += 0.85 * (middle - vertices[c])  # c slides towards edge ab, on the sphere
    vertices[c] /= np.linalg.norm(vertices[c])
    holed = np.delete(triangles, 0, axis=0)
    assert ref.aspect_ratios(vertices, triangles[:1])[0] > 6.5
    for options in ({}, {"refine": True}):
        (patch,) = edit.fill_holes(vertices, holed, **options).patches
        assert patch.triangles.stop - patch.triangles.start == 1
    fair = edit.fill_holes(vertices, holed, fair=True)
    (patch,) = fair.patches
    assert patch.vertices.stop - patch.vertices.start == 1 and patch.triangles.stop - patch.triangles.start == 3
    assert ref.aspect_ratios(fair.vertices, fair.triangles[patch.triangles]).max() <= 5
    lifted = fair.vertices[patch.vertices.start]
    centroid = vertices[[a, b, c]].mean(axis=0)
    normal = np.cross(vertices[b] - vertices[a], vertices[c] - vertices[a])
    rise = np.dot(lifted - centroid, normal / np.linalg.norm(normal))
    assert np.allclose(lifted - centroid, rise * normal / np.linalg.norm(normal))  # straight above
    assert np.dot(normal, centroid) > 0 and 0 < rise < np.linalg.norm(vertices[a] - vertices[b])
    assert summary(fair.vertices, fair.triangles)[:4] == (1, 0, True, True)
    # A well-shaped hole: the faired patch is its own triangle, as the flat one.
    sphere, sphere_triangles = meshgen.icosphere(3)
    good = edit.fill_holes(sphere, np.delete(sphere_triangles, 0, axis=0), fair=True)
    assert good.patches[0].triangles.stop - good.patches[0].triangles.start == 1


# --- remove a handle ------------------------------------------------------------------------------------

def test_remove_handle_torus_both_ways(tmp_path):
    vertices, triangles = meshgen.torus(24, 12)
    for loop in (np.arange(12), np.arange(24) * 12 + 6):  # a meridian, the inner equator
        before = triangles.copy()
        result = edit.remove_handle(vertices, triangles, loop)
        assert np.array_equal(triangles, before)
        assert summary(result.vertices, result.triangles) == (1, 0, True, True, [0])
        assert len(result.patches) == 2 and len(result.cut_sides) == 2
        off_loop = np.setdiff1d(np.arange(len(vertices)), loop)
        assert np.array_equal(result.vertices[off_loop], vertices[off_loop])
        # The loop's copies moved apart, each into its own side, by less than an edge.
        moved = np.linalg.norm(result.vertices - vertices[result.vertex_source], axis=1)
        edges = np.linalg.norm(vertices[triangles] - vertices[np.roll(triangles, 1, axis=1)], axis=2)
        on_cut = np.concatenate([side.vertices for side in result.cut_sides])
        assert np.all(moved[on_cut] > 0.1 * edges.min()) and np.all(moved[on_cut] < 0.5 * edges.max())
        assert np.all(areas(result.vertices, result.triangles) > 0)
        assert directed_edges_unique(result.triangles)
        pairs = cgal_new_intersections(tmp_path, result.vertices, result.triangles, 0)
        if pairs is not None:
            assert pairs == []
        # Without separation the two patches coincide (a cut moves nothing): refused by default
        # (an edit never makes the surface intersect itself), returned when allowed.
        with pytest.raises(ValueError, match="intersect itself"):
            edit.remove_handle(vertices, triangles, loop, separation=0)
        together = edit.remove_handle(vertices, triangles, loop, separation=0, allow_self_intersections=True)
        assert np.array_equal(together.vertices, vertices[together.vertex_source])
        pairs = cgal_new_intersections(tmp_path, together.vertices, together.triangles, 0)
        if pairs is not None:
            assert len(pairs) > 0


@pytest.mark.parametrize("path", genus_meshes(), ids=lambda p: p.stem)
def test_remove_every_handle_until_genus_zero(path):
    """Issue 6: remove one handle loop after another; every step lowers the genus by exactly
    one and keeps one closed, manifold, orientable component with no degenerate triangle; no
    vertex ever moves (cut copies sit where their originals are)."""
    vertices, triangles = read_off(path)
    components, euler = closed_surface_summary(triangles)
    genus = (2 - euler) // 2
    assert components == 1 and genus > 0
    current_v, current_t = vertices, triangles
    source = np.arange(len(vertices))  # current vertex -> original vertex
    on_a_cut = np.zeros(len(vertices), bool)
    for step in range(genus):
        loop = generator_loop(current_v, current_t)
        on_a_cut[source[loop]] = True
        # tree-cotree loops are long and wind around: their flat patches may cross the surface,
        # which remove_handle refuses by default; this test is about the topology of cut + fill
        result = edit.remove_handle(current_v, current_t, loop, allow_self_intersections=True)
        source = source[result.vertex_source]
        current_v, current_t = result.vertices, result.triangles
        assert closed_surface_summary(current_t) == (1, 2 - 2 * (genus - step - 1)), (path.stem, step)
        assert np.all(areas(current_v, current_t) > 0)
    assert generator_loop(current_v, current_t) is None
    assert summary(current_v, current_t) == (1, 0, True, True, [0])  # the slow reference, once
    assert np.all(source >= 0)
    untouched = ~on_a_cut[source]
    assert np.array_equal(current_v[untouched], vertices[source[untouched]])


@pytest.mark.parametrize("path", genus_meshes(), ids=lambda p: p.stem)
@pytest.mark.heavy
def test_remove_handle_loops_from_the_loops_module_until_genus_zero(path):
    """The same with the handle loops of topstoc.core.api.loops (Dey et al.: persistence inside the
    volume, then shortened), removed one after another: the loops found at the start are used
    while all their edges are still there (ids off a cut do not change), else found again."""
    loops = pytest.importorskip("topstoc.core.api.loops", reason="topstoc.core.api.loops is not in this build")
    vertices, triangles = read_off(path)
    genus = (2 - closed_surface_summary(triangles)[1]) // 2
    current_v, current_t = vertices, triangles
    source = np.arange(len(vertices))
    on_a_cut = np.zeros(len(vertices), bool)
    pending = []
    for step in range(genus):
        edges = {tuple(e) for e in ref.undirected_edges(current_t).tolist()}
        pending = [loop for loop in pending
                   if all((min(a, b), max(a, b)) in edges for a, b in zip(loop, np.roll(loop, -1)))]
        if not pending:
            pending = [loop.vertices for loop in loops.handle_tunnel_loops(current_v, current_t).handles]
            assert len(pending) == genus - step
        loop = pending.pop(0)
        on_a_cut[source[loop]] = True
        result = edit.remove_handle(current_v, current_t, loop)
        source = source[result.vertex_source]
        current_v, current_t = result.vertices, result.triangles
        assert closed_surface_summary(current_t) == (1, 2 - 2 * (genus - step - 1)), (path.stem, step)
        assert np.all(areas(current_v, current_t) > 0)
        assert {p.method for p in result.patches} == {"planar"}  # tight loops: flat caps
    untouched = ~on_a_cut[source]
    assert np.array_equal(current_v[untouched], vertices[source[untouched]])


def test_remove_handle_refuses_separating_and_boundary_loops():
    vertices, triangles = meshgen.torus(16, 8)
    with pytest.raises(ValueError, match="separates"):
        edit.remove_handle(vertices, triangles, _one_ring(triangles, 9))  # bounds a disk
    # the two caps of a loop around one vertex lie on top of each other: allowed here on purpose
    result = edit.remove_handle(vertices, triangles, _one_ring(triangles, 9), allow_separating=True,
                                allow_self_intersections=True)
    assert summary(result.vertices, result.triangles)[:2] == (2, 0)
    grid_v, grid_t = meshgen.grid(4, 4)
    with pytest.raises(ValueError, match="mesh boundary"):
        edit.remove_handle(grid_v, grid_t, [2, 8, 13, 12, 11, 6, 7])


def _one_ring(triangles, v):
    """The link of an interior vertex as an ordered cycle."""
    nexts = {}
    for t in triangles:
        for i in range(3):
            if t[i] == v:
                nexts[int(t[(i + 1) % 3])] = int(t[(i + 2) % 3])
    start = next(iter(nexts))
    cycle = [start]
    while nexts[cycle[-1]] != start:
        cycle.append(nexts[cycle[-1]])
    return cycle


# --- attributes and inputs ----------------------------------------------------------------------------

def test_attributes_follow_the_maps():
    vertices, triangles = meshgen.torus(16, 8)
    rng = np.random.default_rng(3)
    uvs = rng.random((len(triangles), 3, 2))
    material = rng.integers(0, 4, len(triangles))
    result = edit.remove_handle(vertices, triangles, np.arange(8))
    carried = result.corner_attribute(uvs)
    old = result.face_source >= 0
    assert np.array_equal(carried[old], uvs[result.face_source[old]])
    flat = result.corner_attribute(uvs.reshape(-1, 2))
    assert np.array_equal(flat.reshape(-1, 3, 2), carried)
    # A patch corner takes the data of a corner at the same vertex in a triangle next to the hole.
    for row in np.flatnonzero(~old):
        for c in range(3):
            source = result.corner_source[row, c]
            assert triangles.ravel()[source] == result.vertex_source[result.triangles[row, c]]
    faces = result.face_attribute(material)
    assert np.array_equal(faces[old], material[result.face_source[old]])
    assert set(faces[~old]) <= set(material)
    assert np.array_equal(result.face_attribute(material, fill=-1)[~old], np.full((~old).sum(), -1))
    with pytest.raises(ValueError, match="one row per input triangle"):
        result.face_attribute(material[:-1])


def test_inputs_are_never_modified_and_any_index_dtype_works():
    vertices, triangles = meshgen.torus(16, 8)
    for dtype_v, dtype_t in ((np.float32, np.int64), (np.float64, np.uint32)):
        v, t = vertices.astype(dtype_v), triangles.astype(dtype_t)
        v0, t0 = v.copy(), t.copy()
        a = edit.remove_handle(v, t, np.arange(8))
        b = edit.fill_holes(*_cut(v, t))
        edit.delete_faces(v, t, [0, 1])
        assert np.array_equal(v, v0) and np.array_equal(t, t0)
        assert summary(a.vertices, a.triangles) == summary(b.vertices, b.triangles)


def _cut(v, t):
    cut = edit.cut_along_loop(v, t, np.arange(8))
    return cut.vertices, cut.triangles


def test_fill_is_deterministic():
    vertices, triangles = meshgen.grid(30, 30)
    centroids = vertices[triangles].mean(axis=1)
    doomed = np.flatnonzero(((centroids[:, 0] % 5) < 2) & ((centroids[:, 1] % 5) < 2) & (centroids[:, 0] > 1) &
                            (centroids[:, 1] > 1) & (centroids[:, 0] < 29) & (centroids[:, 1] < 29))
    holed = edit.delete_faces(vertices, triangles, doomed)
    first = edit.fill_holes(holed.vertices, holed.triangles)
    assert len(first.patches) > 16  # enough holes for the parallel path
    again = edit.fill_holes(holed.vertices, holed.triangles)
    assert np.array_equal(first.triangles, again.triangles)


def test_fill_random_holes_always_closes_the_surface():
    """Property test: random face regions deleted from a sphere, a torus and a genus-2 slab
    (jittered), then every hole filled: always closed, manifold, consistently oriented and
    without a degenerate triangle (lone-triangle pieces left by the deletion are skipped)."""
    rng = np.random.default_rng(7)
    meshes = [meshgen.icosphere(3), meshgen.torus(24, 12), meshgen.genus_slab(2)]
    for trial in range(60):
        vertices, triangles = meshes[trial % 3]
        vertices = vertices + rng.normal(0, 0.01, vertices.shape)
        neighbours = {}
        for f, t in enumerate(triangles):
            for i in range(3):
                neighbours.setdefault(frozenset((t[i], t[(i + 1) % 3])), []).append(f)
        region = set(rng.choice(len(triangles), rng.integers(1, 4), replace=False).tolist())
        frontier, size = list(region), rng.integers(1, 60)
        while len(region) < size and frontier:
            t = triangles[frontier.pop(rng.integers(len(frontier)))]
            for i in range(3):
                for g in neighbours[frozenset((t[i], t[(i + 1) % 3]))]:
                    if g not in region and rng.random() < 0.7:
                        region.add(g)
                        frontier.append(g)
        holed = edit.delete_faces(vertices, triangles, sorted(region))
        loops = edit.boundary_loops(holed.vertices, holed.triangles)
        result = edit.fill_holes(holed.vertices, holed.triangles, skip_unfillable=True)
        assert len(result.patches) >= sum(loop.fillable for loop in loops)
        if all(loop.fillable for loop in loops):
            closed_surface_summary(result.triangles)  # asserts closed, manifold, oriented
        assert np.all(areas(result.vertices, result.triangles) > 0), trial


@pytest.mark.parametrize("name", ["cgal_anchor_dense.off", "cgal_couplingdown.off", "cgal_elephant.off",
                                  "cgal_eight.off"])
def test_removing_every_handle_never_makes_the_surface_intersect_itself(data_dir, tmp_path, name):
    """Issue 17: handle loops found again after every removal (TetGen inside the volume, so
    every intermediate surface must be free of self-intersections), removed one by one down to
    genus 0. Each surface is also checked by the exact self-intersection test (and by CGAL's
    when the peer is built)."""
    loops = pytest.importorskip("topstoc.core.api.loops", reason="topstoc.core.api.loops is not in this build")
    vertices, triangles = read_off(data_dir / "genus_positive" / name)
    genus = (2 - closed_surface_summary(triangles)[1]) // 2
    current_v, current_t = vertices, triangles
    for step in range(genus):
        found = loops.handle_tunnel_loops(current_v, current_t).handles
        assert len(found) == genus - step, (name, step)
        result = edit.remove_handle(current_v, current_t, found[0].vertices)
        current_v, current_t = result.vertices, result.triangles
        assert closed_surface_summary(current_t) == (1, 2 - 2 * (genus - step - 1)), (name, step)
        assert len(loops.self_intersections(current_v, current_t)) == 0, (name, step)
        if step == genus - 1:
            pairs = cgal_new_intersections(tmp_path, current_v, current_t, 0)
            assert not pairs, (name, pairs[:5])
    assert summary(current_v, current_t) == (1, 0, True, True, [0])


def test_remove_handle_steps_down_to_flatter_patches_in_one_call():
    """step_down=True is the sequence faired, refined, flat of separate calls, in one: the same
    arrays as the first of those calls that succeeds, its patches saying what they are."""
    import cleanup_meshes
    from topstoc.core.api.loops import handle_tunnel_loops

    vertices, triangles = cleanup_meshes.block_with_arches(0, 1, large_size=4, jitter=0.05, seed=3)
    loop = min(handle_tunnel_loops(vertices, triangles).handles, key=lambda loop: loop.length).vertices
    with pytest.raises(ValueError, match="intersect itself"):  # a thick handle: faired caps bulge into each other
        edit.remove_handle(vertices, triangles, loop, refine=True, fair=True)
    stepped = edit.remove_handle(vertices, triangles, loop, refine=True, fair=True, step_down=True)
    refined = edit.remove_handle(vertices, triangles, loop, refine=True)
    for name in ("vertices", "triangles", "vertex_source", "face_source", "corner_source"):
        assert np.array_equal(getattr(stepped, name), getattr(refined, name)), name
    assert [(p.refined, p.faired) for p in stepped.patches] == [(True, False)] * 2
    faired = edit.remove_handle(vertices, triangles, loop, refine=True, fair=True, allow_self_intersections=True)
    assert [(p.refined, p.faired) for p in faired.patches] == [(True, True)] * 2
    flat = edit.remove_handle(vertices, triangles, loop)
    assert [(p.refined, p.faired) for p in flat.patches] == [(False, False)] * 2
