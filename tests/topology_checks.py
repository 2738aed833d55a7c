"""Checks shared by the topology tests: GUDHI as the reference for homology, and every claim
about generator edges verified independently (tests/reference.py)."""

import gudhi
import numpy as np

import reference
from topstoc.core.api.topology import topology


def gudhi_betti(num_vertices, triangles, edges=None):
    """Z2 Betti numbers by GUDHI of the complex spanned by the faces: triangles with three
    distinct vertices, the edge spanned by a triangle with a repeated vertex, extra edges, and
    their vertices (a vertex in nothing is no part of the surface; MeshLab counts the same).
    num_vertices is kept for the callers' convenience and not used."""
    tree = gudhi.SimplexTree()
    tri = np.sort(np.asarray(triangles, dtype=np.int64).reshape(-1, 3), axis=1)
    proper = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2])
    if proper.any():
        tree.insert_batch(tri[proper].T.copy(), np.zeros(int(proper.sum())))
    pairs = [sorted(set(t)) for t in tri[~proper].tolist()]
    if edges is not None:
        pairs += [sorted(set(e)) for e in np.asarray(edges).tolist()]
    pairs = [p for p in pairs if len(p) == 2]
    if pairs:
        tree.insert_batch(np.array(pairs).T.copy(), np.zeros(len(pairs)))
    tree.compute_persistence(homology_coeff_field=2, persistence_dim_max=True)
    betti = list(tree.betti_numbers()) + [0, 0, 0]
    return tuple(betti[:3])



def check_generators(vertices, triangles, gens, component_genus):
    """Every claim of ComponentGenerators, checked independently."""
    mesh_edges = {tuple(e) for e in reference.undirected_edges(triangles).tolist()}
    assert [(g.component, g.genus) for g in gens] == component_genus
    for g in gens:
        edges = [tuple(sorted(e)) for e in g.edges.tolist()]
        assert len(edges) == 2 * g.genus == len(set(edges)) == len(g.loops)
        assert [len(loop) for loop in g.loops] == sorted(len(loop) for loop in g.loops)  # shortest first
        assert set(edges) <= mesh_edges
        cut = {tuple(e) for e in g.cut_edges.tolist()}
        assert all(a < b for a, b in cut) and cut <= mesh_edges and set(edges) <= cut
        for edge, loop in zip(g.edges.tolist(), g.loops):
            loop = loop.tolist()
            assert loop[:2] == edge  # starts with its generator edge ...
            assert len(set(loop)) == len(loop) >= 3  # ... and is a simple cycle ...
            pairs = {tuple(sorted(p)) for p in zip(loop, loop[1:] + loop[:1])}
            assert pairs <= mesh_edges  # ... of mesh edges ...
            assert pairs <= cut  # ... inside the cut graph
        # the loops are a basis of H1 over Z2 (2g independent classes = beta1)
        assert reference.homology_rank(triangles, g.loops) == 2 * g.genus
        # cutting the component along the cut graph leaves one disk
        component = topology(vertices, triangles).vertex_component
        own = triangles[component[triangles[:, 0]] == g.component]
        if g.genus:
            count, pieces = reference.cut_along(own, g.cut_edges)
            assert reference.invariants(count, pieces) == [(1, 1, True, True)]


def gudhi_essential_edges(num_vertices, triangles, first, second):
    """Edges GUDHI leaves unpaired when the filtration adds all vertices, then the `first` edges,
    then the `second`, then all other edges, then the triangles."""
    tree = gudhi.SimplexTree()
    for v in range(num_vertices):
        tree.insert([v], 0)
    for e in first:
        tree.insert(sorted(e), 1)
    for e in second:
        tree.insert(sorted(e), 2)
    for e in reference.undirected_edges(triangles).tolist():
        tree.insert(sorted(e), 3)
    for t in np.asarray(triangles).tolist():
        tree.insert(sorted(t), 4)
    tree.compute_persistence(homology_coeff_field=2, persistence_dim_max=True)
    return {tuple(sorted(birth)) for birth, death in tree.persistence_pairs() if len(birth) == 2 and not death}
