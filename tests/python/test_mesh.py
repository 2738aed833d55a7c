"""The prepared mesh: validation, repairs, weights, and what it must never do."""

import time

import numpy as np
import pytest

import meshgen
import reference
from topstoc.core import Mesh


def tetrahedron():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    triangles = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    return vertices, triangles


def test_accepts_float32_and_int64_with_identical_results():
    v, t = meshgen.icosphere(2)
    a = Mesh(v.astype(np.float64), t.astype(np.int32))
    b = Mesh(v.astype(np.float32).astype(np.float64), t.astype(np.int64))
    c = Mesh(v.astype(np.float32), t.astype(np.int64))
    assert a.num_vertices == b.num_vertices == c.num_vertices == len(v)
    np.testing.assert_array_equal(b.weights, c.weights)
    assert a.report().closed and a.report().manifold


def test_weights_follow_eq_4_1_against_independent_formula():
    v, t = meshgen.genus_slab(2, scale=2)
    mesh = Mesh(v, t)
    np.testing.assert_allclose(mesh.weights, reference.importance_weights(v, t), atol=1e-12)
    np.testing.assert_allclose(mesh.normals, reference.area_weighted_normals(v, t), atol=1e-12)
    # a flat grid has zero weight everywhere; the slab's convex edges are the heavy vertices
    flat_v, flat_t = meshgen.grid(6, 6)
    assert np.all(Mesh(flat_v, flat_t).weights < 1e-12)
    assert mesh.weights.max() > 0.1


def test_weights_of_a_mesh_of_many_blocks_follow_eq_4_1():
    """The preparation weighs 16,384 vertices at a time with their neighbours' normals in a ring
    and computes those of neighbours outside it where read: on 100k vertices stored in random
    order, every weight is still eq. 4.1's."""
    v, t = meshgen.bumpy_torus(200_000)
    order = np.random.default_rng(5).permutation(len(v))
    v, t = v[order], np.argsort(order)[t]
    mesh = Mesh(v, t)
    assert mesh.num_vertices > 6 * 16_384
    np.testing.assert_allclose(mesh.weights, reference.importance_weights(v, t), atol=1e-12)
    assert mesh.weights.max() > 0.05


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_neighbours_of_non_manifold_vertices_against_independent_edges(seed):
    # A manifold vertex has as many neighbours as faces (one more on a border) and keeps them in
    # place; a vertex on fins or where fans meet has more and takes the other path. A soup of
    # random triangles over few vertices has both, next to a closed torus and a fin of 5 sheets.
    rng = np.random.default_rng(seed)
    torus_v, torus_t = meshgen.torus(12, 8)
    soup_v = rng.normal(size=(40, 3))
    soup_t = rng.integers(0, 40, size=(300, 3))
    fin_v = np.array([[0, 0, 0], [0, 0, 1]] + [[np.cos(a), np.sin(a), 0.5] for a in np.linspace(0, 6, 5)], float)
    fin_t = np.array([[0, 1, 2 + i] for i in range(5)])
    v, t = meshgen.disjoint((torus_v, torus_t), (soup_v, soup_t), (fin_v, fin_t))
    mesh = Mesh(v, t)
    kept = np.delete(t, mesh.report().dropped_triangles, axis=0)
    expected = np.unique(reference.undirected_edges(kept), axis=0)
    got = np.unique(np.sort(mesh.native.edges, axis=1), axis=0)
    np.testing.assert_array_equal(got, expected)
    assert mesh.native.num_edges == len(expected)
    np.testing.assert_allclose(mesh.weights, reference.importance_weights(v, kept), atol=1e-12)
    assert mesh.report().nonmanifold_edges > 0


def test_report_counts_repairs_and_defects():
    v, t = tetrahedron()
    extra_vertices = np.vstack([v, [[5, 5, 5], [6, 6, 6]]])  # two isolated vertices
    triangles = np.vstack([t,
                           [[0, 0, 1]],        # degenerate: dropped
                           [[2, 0, 1]],        # duplicate of [0, 2, 1] (rotation): dropped
                           [[0, 1, 2]]])       # duplicate, opposite orientation: dropped
    mesh = Mesh(extra_vertices, triangles)
    report = mesh.report()
    assert report.degenerate_triangles == 1
    assert report.duplicate_triangles == 2
    assert list(report.dropped_triangles) == [4, 5, 6]
    assert report.isolated_vertices == 2
    assert mesh.num_triangles == 4
    assert report.components == 1 and report.closed and report.manifold


def test_report_finds_nonmanifold_edges_pinched_vertices_and_flips():
    # three triangles on one edge
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=float)
    fin = Mesh(v, np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))
    assert fin.report().nonmanifold_edges == 1
    assert fin.report().boundary_edges == 6
    # two triangles touching at one vertex (a bow tie)
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], dtype=float)
    bowtie = Mesh(v, np.array([[0, 1, 2], [0, 3, 4]]))
    assert bowtie.report().nonmanifold_vertices == 1 and bowtie.report().components == 1
    # two triangles sharing an edge in the same direction
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    consistent = Mesh(v, np.array([[0, 1, 2], [2, 1, 3]]))
    assert consistent.report().inconsistent_edges == 0
    flipped = Mesh(v, np.array([[0, 1, 2], [1, 2, 3]]))
    assert flipped.report().inconsistent_edges == 1


@pytest.mark.parametrize("bad, message", [
    (lambda v, t: (np.where(np.arange(len(v))[:, None] == 3, np.nan, v), t), "vertex 3 has a non-finite"),
    (lambda v, t: (np.where(np.arange(len(v))[:, None] == 2, np.inf, v), t), "vertex 2 has a non-finite"),
    (lambda v, t: (v, np.vstack([t, [[0, 1, 99]]])), "triangle 4 refers to vertex 99"),
    (lambda v, t: (v, np.vstack([t, [[0, -1, 2]]])), "triangle 4 refers to vertex -1"),
    (lambda v, t: (v[:, :2], t), "shape (n, 3)"),
    (lambda v, t: (v.astype(np.int64), t), "float32 or float64"),
    (lambda v, t: (v, t.astype(float)), "int32 or int64"),
    (lambda v, t: (v, t[:, :2]), "shape (m, 3)"),
    (lambda v, t: (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32)), "no vertices"),
    (lambda v, t: (v, np.zeros((0, 3), dtype=np.int32)), "no triangles"),
    (lambda v, t: (v, np.array([[0, 0, 1], [2, 2, 2]])), "no valid triangles"),
    (lambda v, t: (v, np.array([[0, 1, 2**33]])), "outside the 32-bit index range"),
])
def test_bad_input_raises_a_clear_error(bad, message):
    v, t = tetrahedron()
    vertices, triangles = bad(v, t)
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        Mesh(vertices, triangles)


def test_callers_arrays_are_never_modified():
    v, t = meshgen.torus(12, 8)
    v0, t0 = v.copy(), t.copy()
    mesh = Mesh(v, t)
    mesh.decimate(ratio=0.3, seed=1)
    np.testing.assert_array_equal(v, v0)
    np.testing.assert_array_equal(t, t0)
    assert not mesh.vertices.flags.writeable and not mesh.triangles.flags.writeable


def test_components_and_diagonal():
    mesh = Mesh(*meshgen.disjoint(meshgen.torus(8, 6), meshgen.icosphere(1), meshgen.torus(8, 6)))
    assert mesh.report().components == 3
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    assert mesh.diagonal == pytest.approx(np.linalg.norm(hi - lo))


# -- preparation progress and cancellation (the live preview's Esc) ------------------------------

STEPS = ["validate", "order", "adjacency", "normals and weights", "components"]


def steps_of(stages):
    """The stages in order, each once: the long steps also report inside themselves (at most
    every 50 ms, so on a small mesh only when the machine stalls)."""
    return [stage for i, stage in enumerate(stages) if i == 0 or stages[i - 1] != stage]


def test_progress_hears_every_preparation_step():
    v, t = meshgen.torus(48, 24)
    heard = []
    mesh = Mesh(v, t, progress=lambda fraction, stage: heard.append((fraction, stage)))
    assert steps_of([stage for _, stage in heard]) == STEPS
    fractions = [fraction for fraction, _ in heard]
    assert fractions == sorted(fractions) and fractions[0] == 0.0 and fractions[-1] < 1.0
    plain = Mesh(v, t)
    np.testing.assert_array_equal(mesh.weights, plain.weights)  # progress changes nothing


@pytest.mark.parametrize("stop_at", STEPS)
def test_progress_answering_false_cancels_at_that_step(stop_at):
    from topstoc.core import Cancelled

    v, t = meshgen.torus(48, 24)
    heard = []

    def progress(fraction, stage):
        heard.append(stage)
        return stage != stop_at

    with pytest.raises(Cancelled, match=stop_at):
        Mesh(v, t, progress=progress)
    assert steps_of(heard) == STEPS[:STEPS.index(stop_at) + 1] and heard.count(stop_at) == 1


def test_the_long_preparation_steps_stop_at_cancel_points_inside_them():
    # Progress reports at most every 50 ms; a callback slower than that hears every cancel point.
    # The order step (radix passes over vertices and faces) and the one-ring pass took seconds
    # on 20M triangles with no point to stop at inside them (Esc waited for them to end).
    from topstoc.core import Cancelled

    v, t = meshgen.torus(48, 24)
    heard = []

    def slow(fraction, stage):
        heard.append((stage, fraction))
        time.sleep(0.055)
        return True

    Mesh(v, t, progress=slow)
    stages = [stage for stage, _ in heard]
    assert stages.count("order") >= 10 and stages.count("adjacency") >= 8
    fractions = [fraction for _, fraction in heard]
    assert fractions == sorted(fractions) and fractions[-1] < 1.0

    answered = []

    def cancel_mid_order(fraction, stage):
        answered.append(stage)
        time.sleep(0.055)
        return answered.count("order") < 4  # inside the vertex sort's passes

    with pytest.raises(Cancelled, match="order"):
        Mesh(v, t, progress=cancel_mid_order)
    assert answered == stages[:stages.index("order") + 4]


def test_progress_errors_are_clear():
    v, t = meshgen.torus(12, 6)
    with pytest.raises(TypeError, match="progress must be callable"):
        Mesh(v, t, progress=5)

    def broken(fraction, stage):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):  # the caller's own error comes through
        Mesh(v, t, progress=broken)


def test_vertices_and_triangles_give_back_the_callers_arrays_as_they_were():
    # The engine keeps no copy of the input: both are rebuilt from the prepared mesh (kept
    # faces, the rows of dropped ones), and must equal the input, dropped triangles included,
    # even when the caller changes its arrays afterwards.
    v, t = tetrahedron()
    vertices = np.vstack([v, [[5, 5, 5]]]).astype(np.float32)
    triangles = np.vstack([t, [[0, 0, 1]], [[2, 0, 1]], [[1, 3, 3]], [[0, 1, 2]]]).astype(np.int64)
    expected_v, expected_t = vertices.astype(np.float64), triangles.astype(np.int32)
    mesh = Mesh(vertices, triangles)
    vertices[:] = 0
    triangles[:] = 0
    assert list(mesh.report().dropped_triangles) == [4, 5, 6, 7]
    assert mesh.vertices.dtype == np.float64 and mesh.triangles.dtype == np.int32
    np.testing.assert_array_equal(mesh.vertices, expected_v)
    np.testing.assert_array_equal(mesh.triangles, expected_t)
    shuffled = np.random.default_rng(3).permutation(len(meshgen.torus(12, 8)[0]))
    tv, tt = meshgen.torus(12, 8)
    order = np.argsort(shuffled)
    mesh = Mesh(tv[shuffled], order[tt])
    np.testing.assert_array_equal(mesh.vertices, tv[shuffled])
    np.testing.assert_array_equal(mesh.triangles, order[tt])
