"""Edges of a triangle list and each corner's edge, against a plain numpy reference."""

import numpy as np
import pytest

import meshgen
from threads import outputs_by_thread_count
from topstoc.core import mesh_edges


def reference_edges(triangles):
    """Brute force: every corner's (lower, higher) pair, deduplicated, ordered by lower vertex and
    then by the first corner using the edge (the documented order)."""
    t = np.asarray(triangles, dtype=np.int64)
    pairs = np.stack([t, np.roll(t, -1, axis=1)], axis=-1).reshape(-1, 2)  # corner j -> j + 1
    pairs.sort(axis=1)
    unique, first_corner, corner_edge = np.unique(pairs, axis=0, return_index=True, return_inverse=True)
    order = np.lexsort((first_corner, unique[:, 0]))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return unique[order], rank[corner_edge.reshape(-1)].reshape(-1, 3)


def check_against_reference(triangles, num_vertices):
    edges = mesh_edges(triangles, num_vertices)
    expected, expected_corner_edge = reference_edges(triangles)
    assert edges.vertices.dtype == np.int32 and edges.corner_edge.dtype == np.int32
    assert edges.vertices.shape == expected.shape and edges.corner_edge.shape == (len(triangles), 3)
    np.testing.assert_array_equal(edges.vertices, expected)
    np.testing.assert_array_equal(edges.corner_edge, expected_corner_edge)
    # each corner's edge joins that corner's vertex and the next corner's
    joined = np.sort(edges.vertices[edges.corner_edge], axis=-1)
    own = np.sort(np.stack([triangles, np.roll(triangles, -1, axis=1)], axis=-1), axis=-1)
    np.testing.assert_array_equal(joined, own)
    return edges


@pytest.mark.parametrize("make", [lambda: meshgen.icosphere(3), lambda: meshgen.torus(), lambda: meshgen.grid(7, 5),
                                  meshgen.mobius, meshgen.book, meshgen.tetrahedra_sharing_edge])
def test_matches_reference_on_manifold_boundary_and_nonmanifold_meshes(make):
    vertices, triangles = make()
    check_against_reference(np.asarray(triangles, dtype=np.int32), len(vertices))


def test_euler_count_on_a_closed_surface_and_isolated_vertices():
    vertices, triangles = meshgen.torus(12, 8)
    edges = check_against_reference(triangles, len(vertices) + 5)  # unused vertices add no edges
    assert len(vertices) - len(edges) + len(triangles) == 0        # torus: V - E + F = 0
    assert len(edges) == 3 * len(triangles) // 2


def test_shuffled_large_mesh_int64_input():
    vertices, triangles = meshgen.icosphere(6)  # 40k vertices, 80k triangles
    rng = np.random.default_rng(5)
    order = rng.permutation(len(vertices))
    triangles = order[triangles][rng.permutation(len(triangles))].astype(np.int64)
    check_against_reference(triangles, len(vertices))


def test_empty_and_invalid_input():
    edges = mesh_edges(np.zeros((0, 3), dtype=np.int32), 4)
    assert edges.vertices.shape == (0, 2) and edges.corner_edge.shape == (0, 3)
    with pytest.raises(ValueError, match="refers to vertex 4"):
        mesh_edges(np.array([[0, 1, 4]]), 4)
    with pytest.raises(ValueError, match="repeats a vertex"):
        mesh_edges(np.array([[0, 1, 1]]), 4)
    with pytest.raises(ValueError, match="shape"):
        mesh_edges(np.array([0, 1, 2]), 4)


THREADS_SCRIPT = """
import sys, hashlib, numpy as np
sys.path[:0] = sys.argv[1:3]
import meshgen
from topstoc.core import mesh_edges
vertices, triangles = meshgen.grid(400, 260)  # 105k vertices: above the parallel threshold
order = np.random.default_rng(2).permutation(len(vertices))
edges = mesh_edges(order[triangles], len(vertices))
print(hashlib.sha256(edges.vertices.tobytes() + edges.corner_edge.tobytes()).hexdigest())
"""


@pytest.mark.heavy
def test_serial_and_parallel_runs_agree():
    assert len(set(outputs_by_thread_count(THREADS_SCRIPT).values())) == 1
