"""Drafts (``decimate(draft=True)``): the live preview's frames while a slider moves. A draft
must be the full fast decimation's mesh (the same samples, vertices and triangles), without
the attribute sources and labels and without the final output check, and must say so: its
``output_checked`` is False and its ``topology_kept`` None, never True. Where the full
decimation's plain pass ended above its target and its collapses took it the rest of the way,
or left zero-area triangles its clean-up collapsed, the draft is that plain pass (the collapses
need the labels a draft leaves out, and redoing the frame in full would slow a drag on a
high-genus mesh at a tiny target, or on a scan with collinear points): the same samples, a
superset of the full result's kept vertices.

Every draft here is compared with a full decimation made on a mesh that keeps no flood, so the
comparison also covers drafts that updated a kept flood (the drag's case)."""

import pathlib
import sys

import numpy as np
import pytest

import meshgen
import reference
from topstoc.core import Mesh, TopStocError

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import random_manifolds  # noqa: E402

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
GEOMETRY = ("samples", "kept", "vertices", "triangles")
LEFT_OUT = ("face_source", "corner_source", "labels")


def assert_draft_of(draft, full) -> bool:
    """Checks a draft against the full decimation; False when the frame was made in full (a
    sliver-heavy mesh, collapsed whole: then it must be the full result, checked)."""
    made_in_full = draft.stats.output_checked and not draft.stats.collapses_skipped
    if draft.stats.collapses_skipped:
        assert_first_pass_of(draft, full)
    else:
        assert full.stats.refine_vertices == 0 or made_in_full  # (no collapses left out unsaid)
        for name in GEOMETRY + (LEFT_OUT if made_in_full else ()):
            np.testing.assert_array_equal(getattr(draft, name), getattr(full, name), err_msg=name)
    assert draft.stats.issues_found == full.stats.issues_found
    assert (draft.stats.repairs, draft.stats.top_up) == (full.stats.repairs, full.stats.top_up)
    assert full.stats.output_checked and full.stats.topology_kept
    if made_in_full:
        assert draft.stats.topology_kept and draft.stats.refine_collapses > 0  # (the cleanup or the collapses ran)
        return False
    for name in LEFT_OUT:
        assert len(getattr(draft, name)) == 0, name
    if not draft.stats.fast_path:  # (the fast path's result is checked: see below)
        assert draft.stats.topology_kept is None
        assert draft.stats.seconds["verify"] == 0.0
    return True


def assert_first_pass_of(draft, full):
    """A draft whose full decimation collapsed its plain pass further (it ended above its target
    without stalling, or left zero-area triangles): that pass, whose samples replay the full
    result and whose vertices include the full result's (the collapses keep input positions)."""
    above = draft.num_vertices > draft.stats.target_vertices
    assert above or zero_area_triangles(draft) > 0  # why the full decimation collapsed further
    if above:
        assert full.stats.refine_vertices > 0 and full.stats.refine_keeps_positions
    assert zero_area_triangles(full) == 0 and full.stats.refine_collapses > 0
    assert full.num_vertices <= draft.num_vertices
    np.testing.assert_array_equal(draft.samples, full.samples)
    assert set(full.kept.tolist()) <= set(draft.kept.tolist())


def zero_area_triangles(result) -> int:
    """Triangles whose corners' cross product is exactly zero (the engine's has_zero_area)."""
    a, b, c = (result.vertices[result.triangles[:, k]] for k in range(3))
    return int(np.count_nonzero(np.all(np.cross(b - a, c - a) == 0.0, axis=1)))


@pytest.mark.parametrize("seed", range(12))
def test_a_drag_of_drafts_gives_the_full_meshes(seed):
    """Random hulls, tori, grids with holes, several components and surfaces glued at vertices
    (tests/random_manifolds.py), 12 steps of a drag each."""
    vertices, triangles, ratios, _ = random_manifolds.drag_case(seed, step=0.1)
    mesh, plain = Mesh(vertices, triangles), Mesh(vertices, triangles, keep_floods=False)
    drafts = 0
    for ratio in ratios:
        draft = mesh.decimate(ratio=ratio, seed=seed, mode="fast", draft=True)
        drafts += assert_draft_of(draft, plain.decimate(ratio=ratio, seed=seed, mode="fast"))
    assert drafts >= 10


@pytest.mark.parametrize("name", ["genus_positive/cgal_elephant.off", "open_boundary/cgal_mushroom.off",
                                  "genus0/cgal_fandisk.off", "nonmanifold_degenerate/cgal_degtri_sliding.off"])
def test_real_meshes_with_guidance_creases_and_triangle_targets(name):
    vertices, triangles = reference.read_off(DATA / name)
    mesh, plain = Mesh(vertices, triangles), Mesh(vertices, triangles, keep_floods=False)
    u = np.clip(vertices[:, 0] - vertices[:, 0].mean(), -0.6, 0.6) / max(1e-9, np.ptp(vertices[:, 0]))
    cases = [dict(ratio=0.1, seed=1), dict(ratio=0.03, seed=2, guidance=u), dict(ratio=0.2, seed=3, feature_angle=0.6),
             dict(target_triangles=max(4, len(triangles) // 20), seed=4)]
    drafts = 0
    for options in cases:
        draft = mesh.decimate(mode="fast", draft=True, **options)
        drafts += assert_draft_of(draft, plain.decimate(mode="fast", **options))
    # A sliver-heavy mesh (cgal_degtri_sliding: 8 vertices, zero-area and needle triangles) is
    # collapsed whole in fast mode, so each of its frames is made in full.
    assert drafts == 0 if sliver_share(vertices, triangles) > 0.25 else drafts >= 1


def sliver_share(vertices, triangles):
    """Share of the triangles of shape quality 4 sqrt(3) area / sum of squared edges below 0.1."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    edges = ((b - a) ** 2).sum(1) + ((c - b) ** 2).sum(1) + ((a - c) ** 2).sum(1)
    return float(np.mean(4 * np.sqrt(3) * area < 0.1 * edges))


def test_collinear_vertices_leave_the_draft_its_zero_area_triangles():
    """The zero-area clean-up follows labels and corners, which a draft leaves out: such a frame
    (the genus-133 grid at 5 %, see test_zero_area.py) is the plain pass, zero-area triangles and
    all, and says the full result collapses further."""
    vertices, triangles = meshgen.genus_grid(7, 19, scale=(2, 2, 3))
    mesh = Mesh(vertices, triangles, keep_floods=False)
    frames = 0
    for seed in range(4):
        full = mesh.decimate(ratio=0.05, seed=seed, mode="fast")
        draft = mesh.decimate(ratio=0.05, seed=seed, mode="fast", draft=True)
        assert assert_draft_of(draft, full)
        frames += zero_area_triangles(draft) > 0
        assert draft.stats.collapses_skipped or zero_area_triangles(draft) == 0
    assert frames > 0  # the case was met


def test_the_fast_path_is_always_checked():
    """The fast path's check decides whether to redo its result, so a draft on it is checked."""
    vertices, triangles = reference.read_off(DATA / "genus_positive/cgal_elephant.off")
    mesh = Mesh(vertices, triangles, keep_floods=False)
    draft = mesh.decimate(ratio=0.02, seed=3, mode="fast", fast_path=True, draft=True)
    full = mesh.decimate(ratio=0.02, seed=3, mode="fast", fast_path=True)
    assert draft.stats.output_checked and draft.stats.topology_kept
    assert draft.stats.collapses_skipped  # (98 vertices for 56: the full result's collapses are left out)
    assert_draft_of(draft, full)


@pytest.mark.parametrize("options", [dict(), dict(mode="quality"), dict(mode="fast", refine=2.0),
                                     dict(mode="fast", max_error=0.01, ratio=None)])
def test_a_draft_is_plain_topstoc_only(options):
    mesh = Mesh(*meshgen.torus(24, 12))
    options = dict(dict(ratio=0.2), **options)
    if options["ratio"] is None:
        del options["ratio"]
    with pytest.raises(TopStocError, match="draft"):
        mesh.decimate(draft=True, **options)
