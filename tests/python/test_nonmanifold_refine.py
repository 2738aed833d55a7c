"""Quality mode on non-manifold input: sheets meeting along an edge are simplified, not frozen.

A non-manifold edge is a feature curve: the collapses may shorten it (each sheet keeps one fan
on its side) but never remove a sheet. Checked with tests/reference.py, independent of the engine.
"""

import pathlib

import numpy as np

import reference
from topstoc.core import Mesh, read_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


def three_sheets(length=40, width=12):
    """Three strips (width x length vertices) sharing their first row, the spine along x: every
    spine edge has three triangles. Gently curved so the quadrics see some shape."""
    spine = [(x, 0.0, 0.0) for x in range(length)]
    vertices = list(spine)
    triangles = []
    for k in range(3):
        angle = 2 * np.pi * k / 3
        direction = np.array([0.0, np.cos(angle), np.sin(angle)])
        rows = [list(range(length))]
        for j in range(1, width):
            row = []
            for x in range(length):
                p = j * direction + np.array([x, 0.0, 0.0]) + [0.0, 0.0, 0.02 * j * j * np.sin(x / 7.0)]
                row.append(len(vertices))
                vertices.append(tuple(p))
            rows.append(row)
        for j in range(width - 1):
            for x in range(length - 1):
                a, b, c, d = rows[j][x], rows[j][x + 1], rows[j + 1][x], rows[j + 1][x + 1]
                triangles += [(a, b, d), (a, d, c)]
    return np.array(vertices, dtype=float), np.array(triangles, dtype=np.int64), length


def spine_edges(triangles):
    edges, counts = np.unique(reference.undirected_edges(np.asarray(triangles)), axis=0, return_counts=True)
    return edges[counts > 2], counts[counts > 2]


def test_a_non_manifold_curve_is_shortened_and_keeps_its_three_sheets():
    vertices, triangles, length = three_sheets()
    mesh = Mesh(vertices, triangles)
    expected = reference.invariants(len(vertices), triangles)
    r = mesh.decimate(ratio=0.05, seed=0)
    kept = np.asarray(r.kept)
    on_spine = int(np.count_nonzero(kept < length))
    # The old collapser refused every edge with three triangles: all 40 spine vertices stayed.
    assert on_spine < length // 2, on_spine
    edges, counts = spine_edges(r.triangles)
    assert len(edges) == on_spine - 1 and np.all(counts == 3)  # one curve, three sheets all along
    assert reference.invariants(r.num_vertices, r.triangles) == expected
    assert reference.degenerate_or_duplicate(r.triangles) == (0, 0)
    assert not any(r.stats.output_check.values())


def test_a_scan_with_non_manifold_edges_gets_nearer_its_target():
    # Stanford's dragon at its lowest resolution: 494 non-manifold edges (curves of one or two
    # edges, mostly, whose ends are kept corners), 5 pinched vertices and 90 inconsistently
    # oriented edges. The rings of every vertex on a non-manifold edge were frozen, so 10 %
    # stopped at half the input (5,542 triangles of 11,102); now 2,528, the corners (546
    # vertices) and the rings of the inconsistent edges setting the floor.
    data = read_mesh(DATA / "nonmanifold_degenerate/dragon_vrip_res4.ply.gz")
    mesh = Mesh(data.vertices, data.triangles)
    # (as the engine reads it: its duplicate triangles dropped)
    cleaned = np.delete(np.asarray(mesh.triangles), mesh.report().dropped_triangles, axis=0)
    expected = reference.invariants(len(mesh.vertices), cleaned)
    r = mesh.decimate(target_triangles=1110, seed=0)
    assert r.num_triangles < 2750, r.num_triangles  # under half of before
    # the kept corners of the non-manifold curves (borders) outnumber the target: the reason says so
    assert r.stats.over_budget_reason == "borders" and r.stats.forced >= r.stats.target_vertices
    assert reference.invariants(r.num_vertices, r.triangles) == expected
    assert reference.degenerate_or_duplicate(r.triangles) == (0, 0)
    assert not any(r.stats.output_check.values())


def inconsistent_edges(triangles):
    """Edges whose two triangles run along them the same way (numpy, independent of the engine)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    _, inverse, counts = np.unique(undirected, axis=0, return_inverse=True, return_counts=True)
    forward = np.bincount(inverse.ravel(), weights=(directed[:, 0] < directed[:, 1]), minlength=len(counts))
    return int(np.count_nonzero((counts == 2) & ((forward == 0) | (forward == 2))))


def test_an_inconsistently_oriented_edge_is_not_collapsed_away():
    # assimp's spider: 10 inconsistently oriented edges. The collapses removed all of them, so
    # its components came out consistently oriented: a changed topology.
    data = read_mesh(DATA / "uv_materials/spider/spider.obj")
    mesh = Mesh(data.vertices, data.triangles)
    assert inconsistent_edges(mesh.triangles) > 0
    for ratio in (0.1, 0.02):
        r = mesh.decimate(ratio=ratio, seed=0)
        assert inconsistent_edges(r.triangles) > 0, ratio
        assert not any(r.stats.output_check.values())
