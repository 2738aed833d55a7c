"""Inconsistently oriented input (patches of flipped triangles, as exports and merged parts
have): each orientable component is decimated in one winding (the engine's Mesh::winding_flips),
and each output triangle takes its source face's winding back. So fast mode's plain pass meets
its target without falling back to collapses, and the output keeps the input's flipped patches
where it keeps their triangles, at least one seam per component. Checked with numpy and
tests/reference.py, independent of the engine."""

import numpy as np
import pytest

import meshgen
import reference
from test_nonmanifold_refine import inconsistent_edges
from topstoc.core import Mesh

MODES = ["quality", "fast"]


def flipped_torus(triangles=20000, half=True):
    """The bumpy torus with half of it (a band around the ring) or a tenth of its triangles at
    random wound the other way."""
    vertices, faces = meshgen.bumpy_torus(triangles)
    faces = faces.copy()
    if half:
        centre = vertices[faces].mean(axis=1)
        flip = np.arctan2(centre[:, 1], centre[:, 0]) < 0
    else:
        flip = np.random.default_rng(3).random(len(faces)) < 0.1
    faces[flip] = faces[flip][:, ::-1]
    return vertices, faces


def normals(vertices, triangles):
    v = np.asarray(vertices)[np.asarray(triangles)]
    return np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])


def winding_agreement(vertices, faces, result):
    """Share of the output triangles that face the way their source face does."""
    ours = normals(result.vertices, result.triangles)
    theirs = normals(vertices, faces[np.asarray(result.face_source)])
    return float(np.mean(np.einsum("ij,ij->i", ours, theirs) > 0))


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("half", [True, False])
def test_flipped_patches_are_decimated_in_one_winding_and_given_theirs_back(mode, half):
    vertices, faces = flipped_torus(half=half)
    assert inconsistent_edges(faces) > 100
    consistent = meshgen.bumpy_torus(20000)[1]
    mesh = Mesh(vertices, faces)
    r = mesh.decimate(ratio=0.05, seed=0, mode=mode)
    assert r.stats.target_missed is None
    assert r.stats.topology_kept
    assert reference.invariants(r.num_vertices, r.triangles) == reference.invariants(len(vertices), faces)
    assert reference.degenerate_or_duplicate(r.triangles) == (0, 0)
    assert inconsistent_edges(r.triangles) > 0
    # Each triangle faces the way its source face does, as often as on the consistent torus.
    baseline = Mesh(vertices, consistent).decimate(ratio=0.05, seed=0, mode=mode)
    assert winding_agreement(vertices, faces, r) >= winding_agreement(vertices, consistent, baseline) - 0.005
    assert winding_agreement(vertices, faces, r) > 0.98
    if mode == "fast":
        # The plain pass alone (before, its repairs stalled on every seam and the collapses
        # took the whole mesh), and each corner's source corner holds the vertex it keeps.
        assert r.stats.refine_collapses == 0
        corner_vertex = faces.reshape(-1)[np.asarray(r.corner_source).reshape(-1)]
        np.testing.assert_array_equal(corner_vertex, np.asarray(r.kept)[np.asarray(r.triangles).reshape(-1)])


def test_a_draft_has_the_windings_of_the_full_result():
    vertices, faces = flipped_torus()
    mesh = Mesh(vertices, faces)
    full = mesh.decimate(ratio=0.05, seed=0, mode="fast")
    draft = mesh.decimate(ratio=0.05, seed=0, mode="fast", draft=True)
    np.testing.assert_array_equal(np.asarray(draft.triangles), np.asarray(full.triangles))


def test_one_seam_per_component_stays():
    # Two tori, one with a single flipped triangle, at a tenth of a percent: the flipped
    # triangle and its neighbour across one edge stay, each with its own winding.
    a_vertices, a_faces = meshgen.bumpy_torus(8000)
    b_vertices, b_faces = meshgen.bumpy_torus(8000)
    a_faces = a_faces.copy()
    a_faces[100] = a_faces[100][::-1]
    vertices = np.vstack([a_vertices, b_vertices + 5.0])
    faces = np.vstack([a_faces, b_faces + len(a_vertices)])
    assert inconsistent_edges(faces) == 3
    for mode in MODES:
        r = Mesh(vertices, faces).decimate(target_triangles=60, seed=0, mode=mode)
        assert 100 in set(np.asarray(r.face_source).tolist()), mode
        assert inconsistent_edges(r.triangles) >= 1, mode
        assert reference.invariants(r.num_vertices, r.triangles) == reference.invariants(len(vertices), faces)
