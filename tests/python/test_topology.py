"""Topology invariants and generator edges against GUDHI, brute-force references and known
surfaces (issue 4). Shared meshes are covered in test_topology_shared.py."""

import numpy as np
import pytest

import meshgen
import reference
from topstoc.core.api.topology import generators, topology

gudhi = pytest.importorskip("gudhi")
from topology_checks import check_generators, gudhi_betti, gudhi_essential_edges  # noqa: E402


def with_isolated(mesh, count):
    vertices, triangles = mesh
    return np.concatenate([vertices, np.full((count, 3), 7.0)]), triangles


def mixed_complex():
    """A torus, a Moebius strip, a wire edge hanging off a sphere, a K4 graph and a lone vertex."""
    vertices, triangles = meshgen.disjoint(meshgen.torus(12, 8), meshgen.mobius(), meshgen.icosphere(1))
    n = len(vertices)
    graph = meshgen.complete_graph(4)[0] + [0, 9, 0]
    vertices = np.concatenate([vertices, [[0, 0, 9.0]], graph, [[5, 5, 5.0]]])
    edges = np.array([[n - 1, n]] + [[n + 1 + a, n + 1 + b] for a in range(4) for b in range(a + 1, 4)])
    return vertices, triangles, edges


SYNTHETIC = {
    "sphere": (*meshgen.icosphere(2), None),
    "torus": (*meshgen.torus(), None),
    "genus 2": (*meshgen.genus_slab(2), None),
    "genus 3": (*meshgen.genus_slab(3), None),
    "genus 5": (*meshgen.genus_slab(5, scale=1), None),
    "two tori": (*meshgen.disjoint(meshgen.torus(), meshgen.torus(12, 8)), None),
    "disk": (*meshgen.grid(5, 4), None),
    "moebius": (*meshgen.mobius(), None),
    "klein bottle": (*meshgen.klein_bottle(), None),
    "projective plane": (*meshgen.projective_plane(), None),
    "pinched torus": (*meshgen.pinched_sphere(), None),
    "three disks on a circle": (*meshgen.theta_surface(), None),
    "book": (*meshgen.book(4), None),
    "tetrahedra on an edge": (*meshgen.tetrahedra_sharing_edge(), None),
    "edge graph K5": meshgen.complete_graph(5),
    "isolated vertices": (*with_isolated(meshgen.torus(8, 6), 3), None),
    "only isolated vertices": (np.zeros((4, 3)), np.zeros((0, 3), np.int32), None),
    "mixed": mixed_complex(),
}


@pytest.mark.parametrize("name", SYNTHETIC)
def test_betti_numbers_equal_gudhi(name):
    vertices, triangles, edges = SYNTHETIC[name]
    info = topology(vertices, triangles, edges)
    assert info.betti == gudhi_betti(len(vertices), triangles, edges)
    isolated = len(info.isolated_vertices)
    # the surface's numbers: isolated vertices are listed apart and counted in none
    assert info.betti == tuple(np.sum([c.betti for c in info.components] + [(0, 0, 0)], axis=0))
    assert info.euler == info.betti[0] - info.betti[1] + info.betti[2]
    # Euler-Poincare per component, and totals
    for c in info.components:
        assert c.euler == c.vertices - c.edges + c.faces == c.betti[0] - c.betti[1] + c.betti[2]
    assert sum(c.vertices for c in info.components) + isolated == len(vertices)
    assert np.array_equal(np.flatnonzero(info.vertex_component < 0), info.isolated_vertices)


@pytest.mark.parametrize("seed", range(25))
def test_random_complexes_equal_gudhi(seed):
    """Random triangles on few vertices: many edges of 3+ triangles, pinched vertices, wires,
    repeats and collapsed triangles, all at once (the Z2 system for beta2 gets exercised)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 14))
    triangles = rng.integers(0, n, size=(int(rng.integers(1, 40)), 3))
    edges = rng.integers(0, n, size=(int(rng.integers(0, 6)), 2))
    vertices = rng.random((n + int(rng.integers(0, 3)), 3))
    info = topology(vertices, triangles, edges)
    assert info.betti == gudhi_betti(len(vertices), triangles, edges)
    assert sum(c.edges for c in info.components) == info.edges
    for c in info.components:
        assert c.euler == c.betti[0] - c.betti[1] + c.betti[2]


EXPECTED = {  # name: per component (kind, betti, closed, orientable, manifold, genus, crosscaps, loops)
    "sphere": [("surface", (1, 0, 1), True, True, True, 0, None, 0)],
    "torus": [("surface", (1, 2, 1), True, True, True, 1, None, 0)],
    "genus 3": [("surface", (1, 6, 1), True, True, True, 3, None, 0)],
    "genus 5": [("surface", (1, 10, 1), True, True, True, 5, None, 0)],
    "disk": [("surface", (1, 0, 0), False, True, True, 0, None, 1)],
    "moebius": [("surface", (1, 1, 0), False, False, True, None, 1, 1)],
    "klein bottle": [("surface", (1, 2, 1), True, False, True, None, 2, 0)],
    "projective plane": [("surface", (1, 1, 1), True, False, True, None, 1, 0)],
    "pinched torus": [("surface", (1, 1, 1), True, True, False, None, None, 0)],
    "three disks on a circle": [("surface", (1, 0, 2), True, None, False, None, None, 0)],
    "tetrahedra on an edge": [("surface", (1, 0, 2), True, None, False, None, None, 0)],
    "edge graph K5": [("graph", (1, 6, 0), None, None, None, None, None, 0)],
    "mixed": [("surface", (1, 2, 1), True, True, True, 1, None, 0),
              ("surface", (1, 1, 0), False, False, True, None, 1, 1),
              ("surface", (1, 0, 1), True, True, False, None, None, 0),  # sphere with a wire edge
              ("graph", (1, 3, 0), None, None, None, None, None, 0)],
}


@pytest.mark.parametrize("name", EXPECTED)
def test_classification(name):
    vertices, triangles, edges = SYNTHETIC[name]
    info = topology(vertices, triangles, edges)
    got = [(c.kind, c.betti, c.closed, c.orientable, c.manifold, c.genus, c.crosscaps, len(c.boundary_loops))
           for c in info.components]
    assert got == EXPECTED[name]


def test_summaries():
    summary = lambda mesh, edges=None: [c.summary for c in topology(*mesh, edges).components]  # noqa: E731
    assert summary(meshgen.genus_slab(3)) == ["genus 3, closed, orientable"]
    assert summary(meshgen.grid(2, 2)) == ["genus 0, 1 boundary loop, orientable"]
    assert summary(meshgen.mobius()) == ["non-orientable, 1 cross-cap, 1 boundary loop"]
    assert summary(meshgen.klein_bottle()) == ["non-orientable, 2 cross-caps, closed"]
    assert summary(meshgen.book(3)) == [
        "non-manifold (1 edge, 2 vertices), 3 open boundary chains, genus undefined, betti 1/0/0"]
    vertices, _, edges = meshgen.complete_graph(4)
    assert summary((vertices, np.zeros((0, 3), int)), edges) == ["edge graph, 3 independent cycles"]
    assert topology(*with_isolated(meshgen.torus(8, 6), 2)).summary() == \
        "1 component: genus 1, closed, orientable, 2 isolated vertices"
    assert topology(*with_isolated(meshgen.disjoint(meshgen.torus(8, 6), meshgen.grid(2, 2)), 1)).summary() == \
        "2 components (2 surfaces), 1 isolated vertex, betti 2/2/1"
    assert topology(np.zeros((3, 3)), np.zeros((0, 3), int)).summary() == "3 isolated vertices"


@pytest.mark.parametrize("name", ["sphere", "torus", "genus 2", "two tori", "disk", "moebius", "klein bottle",
                                  "projective plane", "pinched torus", "three disks on a circle"])
def test_components_match_brute_force(name):
    """Euler characteristic, boundary loops, manifoldness and orientability per component against
    the plain reference implementation (tests/reference.py)."""
    vertices, triangles, _ = SYNTHETIC[name]
    info = topology(vertices, triangles)
    ours = sorted(((c.euler, len(c.boundary_loops) + len(c.boundary_paths), c.manifold,
                    c.orientable if c.manifold else None) for c in info.components if c.kind == "surface"),
                  key=lambda x: (x[0], x[1], x[2]))
    assert ours == reference.invariants(len(vertices), triangles)


def boundary_edge_set(triangles):
    edges, counts = np.unique(reference.undirected_edges(triangles), axis=0, return_counts=True)
    return {tuple(e) for e in edges[counts == 1].tolist()}


@pytest.mark.parametrize("name", ["disk", "moebius", "mixed"])
def test_boundary_loops_cover_the_boundary(name):
    vertices, triangles, edges = SYNTHETIC[name]
    info = topology(vertices, triangles, edges)
    directed = {tuple(s) for t in np.asarray(triangles).tolist() for s in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    walked = []
    for c in info.components:
        for loop in c.boundary_loops:
            assert len(set(loop.tolist())) == len(loop)  # simple cycle
            pairs = list(zip(loop.tolist(), np.roll(loop, -1).tolist()))
            assert pairs[0] in directed  # the first edge follows its triangle's corner order
            walked += [(min(a, b), max(a, b)) for a, b in pairs]
            assert np.all(info.vertex_component[loop] == c.index)
    assert sorted(walked) == sorted(boundary_edge_set(triangles))


def test_boundary_loop_orientation_follows_consistent_triangles():
    vertices, triangles = meshgen.disjoint(meshgen.grid(4, 3), meshgen.grid(2, 2))
    directed = {tuple(s) for t in triangles.tolist() for s in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    for c in topology(vertices, triangles).components:
        (loop,) = c.boundary_loops
        assert all(pair in directed for pair in zip(loop.tolist(), np.roll(loop, -1).tolist()))


def test_open_boundary_chains_at_nonmanifold_edges():
    vertices, triangles = meshgen.book(3)  # pages (0, 1, k): the spine (0, 1) has 3 triangles
    (c,) = topology(vertices, triangles).components
    assert c.boundary_loops == []
    assert sorted(p.tolist() for p in c.boundary_paths) == [[1, 2, 0], [1, 3, 0], [1, 4, 0]]
    assert c.nonmanifold_edges.tolist() == [[0, 1]] and c.nonmanifold_edge_faces.tolist() == [3]
    assert c.nonmanifold_vertices.tolist() == [0, 1]


def test_nonmanifold_elements_listed():
    (c,) = topology(*meshgen.pinched_sphere()).components
    assert c.nonmanifold_edges.shape == (0, 2) and c.nonmanifold_vertices.tolist() == [0]
    (c,) = topology(*meshgen.tetrahedra_sharing_edge()).components
    assert c.nonmanifold_edges.tolist() == [[0, 1]] and c.nonmanifold_edge_faces.tolist() == [4]
    vertices, triangles, edges = mixed_complex()
    sphere = topology(vertices, triangles, edges).components[2]
    wire = edges[0].tolist()
    assert sphere.nonmanifold_edges.tolist() == [wire] and sphere.nonmanifold_edge_faces.tolist() == [0]
    assert sphere.nonmanifold_vertices.tolist() == wire


def test_inconsistent_orientation_is_reported_not_fatal():
    vertices, triangles = meshgen.genus_slab(2)
    flipped = triangles.copy()
    flipped[::7] = flipped[::7, ::-1]
    (c,) = topology(vertices, flipped).components
    assert (c.genus, c.orientable, c.consistently_oriented) == (2, True, False)
    assert c.summary == "genus 2, closed, orientable (triangles inconsistently oriented)"
    assert topology(vertices, triangles).components[0].consistently_oriented is True


def test_collapsed_and_duplicate_triangles():
    vertices, triangles = meshgen.torus(8, 6)
    n = len(vertices)
    vertices = np.concatenate([vertices, [[9, 9, 9.0], [9, 9, 8.0]]])
    extra = np.array([
        triangles[3][::-1],           # duplicate, flipped
        np.roll(triangles[5], 1),     # duplicate, rotated
        triangles[5],                 # duplicate again
        [n, n, n + 1],                # collapsed: the edge (n, n+1), a new component
        [0, 0, 1],                    # collapsed onto an existing edge: changes nothing
        [2, 2, 2],                    # collapsed to a vertex
        [0, n, 0],                    # collapsed: a wire edge joining the torus to the new edge
    ])
    all_triangles = np.concatenate([triangles, extra]).astype(np.int32)
    info = topology(vertices, all_triangles)
    assert (info.duplicate_triangles, info.collapsed_triangles) == (3, 4)
    assert info.faces == len(triangles)
    assert info.betti == gudhi_betti(len(vertices), all_triangles) == (1, 2, 1)
    (c,) = info.components
    assert c.manifold is False and sorted(c.nonmanifold_edges.tolist()) == [[0, n], [n, n + 1]]
    # the duplicates do not change the surface invariants
    clean = topology(vertices[:n], np.concatenate([triangles, extra[:3]]))
    assert clean.components[0].summary == "genus 1, closed, orientable"
    assert clean.duplicate_triangles == 3


def test_duplicates_at_nonmanifold_edges():
    vertices, triangles = meshgen.book(3)
    doubled = np.concatenate([triangles, triangles[:, ::-1]])
    info = topology(vertices, doubled)
    assert info.duplicate_triangles == 3 and info.faces == 3
    assert info.betti == gudhi_betti(len(vertices), doubled) == (1, 0, 0)


def test_invariant_under_relabeling():
    rng = np.random.default_rng(5)
    vertices, triangles = meshgen.disjoint(meshgen.genus_slab(2), meshgen.mobius(), meshgen.grid(3, 3))
    perm = rng.permutation(len(vertices))
    inverse = np.argsort(perm)
    relabeled = inverse[triangles][rng.permutation(len(triangles))]
    relabeled = np.roll(relabeled, 1, axis=1)
    key = lambda info: sorted((c.vertices, c.edges, c.faces, c.betti, c.genus, c.crosscaps, c.closed,  # noqa: E731
                               c.orientable, len(c.boundary_loops)) for c in info.components)
    assert key(topology(vertices[perm], relabeled)) == key(topology(vertices, triangles))


def test_isolated_vertices_listed_apart():
    vertices, triangles = with_isolated(meshgen.torus(8, 6), 3)
    vertices = np.concatenate([np.full((2, 3), 5.0), vertices])  # two more, before the torus
    info = topology(vertices, triangles + 2)
    assert info.isolated_vertices.tolist() == [0, 1, 50, 51, 52]
    assert info.betti == (1, 2, 1) and [c.first_vertex for c in info.components] == [2]
    assert info.euler == 0 and "5 isolated vertices" in info.summary()
    assert info.vertex_component.tolist() == [-1, -1] + [0] * 48 + [-1] * 3
    assert info.to_dict()["isolated_vertices"] == [0, 1, 50, 51, 52]
    cloud = topology(np.random.default_rng(1).random((200000, 3)), np.zeros((0, 3), np.int32))
    assert cloud.betti == (0, 0, 0) and cloud.components == [] and len(cloud.isolated_vertices) == 200000


def test_components_numbered_by_smallest_vertex():
    vertices, triangles = meshgen.disjoint(meshgen.torus(8, 6), meshgen.icosphere(1))
    shifted = np.concatenate([vertices[48:], vertices[:48]])
    triangles = np.where(triangles < 48, triangles + len(vertices) - 48, triangles - 48)
    info = topology(shifted, triangles)
    assert [c.first_vertex for c in info.components] == [0, len(vertices) - 48]
    assert [c.genus for c in info.components] == [0, 1]
    assert np.array_equal(info.triangle_component(triangles), info.vertex_component[triangles[:, 0]])


def test_to_dict_has_the_cli_keys():
    data = topology(*meshgen.grid(2, 2)).to_dict()
    assert data["betti"] == [1, 0, 0]
    (c,) = data["components"]
    for key in ("vertices", "edges", "faces", "euler", "betti", "closed", "orientable", "manifold", "genus",
                "boundary_loops"):
        assert key in c
    assert (c["vertices"], c["edges"], c["faces"], c["euler"], c["genus"]) == (9, 16, 8, 1, 0)
    assert sorted(c["boundary_loops"][0]) == [0, 1, 2, 3, 5, 6, 7, 8]


# --- bad input (docs/design.md §5) --------------------------------------------------------------

def test_empty_mesh():
    info = topology(np.zeros((0, 3)), np.zeros((0, 3), np.int32))
    assert info.betti == (0, 0, 0) and info.components == [] and info.summary() == "empty"
    assert info.isolated_vertices.shape == (0,)
    assert generators(np.zeros((0, 3)), np.zeros((0, 3), np.int32)) == []


@pytest.mark.parametrize("vertices, triangles, edges, message", [
    (np.array([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]]), [[0, 1, 2]], None, "vertex 1 has a non-finite"),
    (np.array([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]]), [[0, 1, 2]], None, "vertex 2 has a non-finite"),
    (np.zeros((3, 3)), [[0, 1, 2], [0, 1, 3]], None, "triangle 1 refers to vertex 3"),
    (np.zeros((3, 3)), [[0, -1, 2]], None, "triangle 0 refers to vertex -1"),
    (np.zeros((3, 3)), [[0, 1, 2]], [[0, 1], [2, 5]], "edge 1 refers to vertex 5"),
    (np.zeros((3, 3)), np.array([[0.0, 1.0, 2.0]]), None, "triangles must be an int32 or int64 array"),
    (np.zeros((3, 3)), np.array([[0, 1, 2, 0]]), None, "triangles must be an int32 or int64 array of shape (m, 3)"),
    (np.zeros((3, 2)), [[0, 1, 2]], None, "vertices must be a float32 or float64 array of shape (n, 3)"),
    (np.zeros((3, 3), dtype=np.int32), [[0, 1, 2]], None, "vertices must be a float32 or float64"),
    (np.zeros((3, 3)), None, None, "triangles is None"),
    (np.zeros((3, 3)), [[0, 1, 2]], [[0, 1, 2]], "edges must be an int32 or int64 array of shape (m, 2)"),
    (np.zeros((3, 3)), [[0, 1, 2**33]], None, "outside the 32-bit index range"),
])
def test_bad_input_raises_clear_errors(vertices, triangles, edges, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        topology(vertices, np.asarray(triangles) if triangles is not None else None, edges)


def test_caller_arrays_untouched():
    vertices, triangles = meshgen.torus(8, 6)
    vertices = vertices.astype(np.float32)
    triangles = np.concatenate([triangles, triangles[:2], [[0, 0, 1]]]).astype(np.int64)
    before = (vertices.copy(), triangles.copy())
    vertices.setflags(write=False)
    triangles.setflags(write=False)
    generators(vertices, triangles)
    topology(vertices, triangles)
    assert np.array_equal(vertices, before[0]) and np.array_equal(triangles, before[1])


# --- generators ----------------------------------------------------------------------------

@pytest.mark.parametrize("mesh, genus", [(meshgen.torus(), 1), (meshgen.torus(5, 3), 1),
                                          (meshgen.genus_slab(2), 2), (meshgen.genus_slab(3, scale=1), 3)])
def test_generators_of_synthetic_surfaces(mesh, genus):
    vertices, triangles = mesh
    gens = generators(vertices, triangles)
    check_generators(vertices, triangles, gens, [(0, genus)])
    # They are the unpaired edges of a persistence pairing (GUDHI): all vertices, the cut graph's
    # tree edges, the generators, then the rest.
    (g,) = gens
    generator_set = {tuple(sorted(e)) for e in g.edges.tolist()}
    tree_edges = [e for e in g.cut_edges.tolist() if tuple(e) not in generator_set]
    assert gudhi_essential_edges(len(vertices), triangles, tree_edges, generator_set) == generator_set


def test_generators_only_for_closed_orientable_manifold_components():
    vertices, triangles = meshgen.disjoint(meshgen.grid(3, 3), meshgen.torus(12, 8), meshgen.klein_bottle(),
                                           meshgen.pinched_sphere(), meshgen.icosphere(1), meshgen.genus_slab(2))
    gens = generators(vertices, triangles)
    check_generators(vertices, triangles, gens, [(1, 1), (4, 0), (5, 2)])
    assert gens[1].edges.shape == (0, 2) and gens[1].loops == [] and gens[1].cut_edges.shape == (0, 2)


def test_generators_with_inconsistent_orientation_and_relabeling():
    rng = np.random.default_rng(11)
    vertices, triangles = meshgen.genus_slab(2)
    perm = rng.permutation(len(vertices))
    triangles = np.argsort(perm)[triangles][rng.permutation(len(triangles))]
    triangles[::5] = triangles[::5, ::-1]
    vertices = vertices[perm]
    check_generators(vertices, triangles, generators(vertices, triangles), [(0, 2)])


def test_generators_are_deterministic():
    vertices, triangles = meshgen.genus_slab(3)
    a, b = generators(vertices, triangles)[0], generators(vertices, triangles)[0]
    assert np.array_equal(a.edges, b.edges) and np.array_equal(a.cut_edges, b.cut_edges)
    assert all(np.array_equal(x, y) for x, y in zip(a.loops, b.loops))


def test_topology_with_generators_flag():
    info = topology(*meshgen.torus(), generators=True)
    assert len(info.generators) == 1 and info.generators[0].genus == 1
    assert "generators" in info.to_dict()
    assert topology(*meshgen.torus()).generators == []
