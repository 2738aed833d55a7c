"""Scenes of many tiny components (leaf and grass cards, hair strips: tests/shape_families.py):
each card keeps its topology (a disc, so at least one triangle), a card at that floor passes
through the collapses untouched, and the cards do not hold back the collapses of a big mesh
beside them. Components and their invariants are counted by tests/reference.py, independent of
the engine."""

import numpy as np
import pytest

import meshgen
import shape_families
from reference import components, invariants
from topstoc.core import Mesh

MODES = ["quality", "fast"]


def card_of_vertex(cards):
    """Input card of each input vertex of foliage_cards (four vertices a card)."""
    return np.arange(4 * cards) // 4


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("ratio", [0.01, 0.3])
def test_cards_at_their_floor_keep_one_input_triangle_each(mode, ratio):
    vertices, faces = shape_families.foliage_cards(4000)
    cards = len(faces) // 2
    result = Mesh(vertices, faces).decimate(ratio=ratio, mode=mode, seed=1)
    assert result.num_triangles == cards  # one triangle a card: a disc's floor
    missed = result.stats.target_missed
    assert missed is not None and missed.reason == "topology"
    # the detail names the pieces, and no welding: the input's own triangles are not loose
    assert f"{cards:,} of the result's {cards:,} triangles are separate pieces of the input" in missed.detail
    assert "weld" not in missed.detail
    # each output triangle lies on one card, and every card has one
    source_card = np.asarray(result.face_source) // 2
    assert sorted(source_card.tolist()) == list(range(cards))
    out = np.asarray(result.triangles)
    labels = np.asarray(result.labels)
    owner = np.full(len(result.vertices), -1)
    owner[labels[labels >= 0]] = card_of_vertex(cards)[labels >= 0]
    assert np.all(owner[out] == source_card[:, None])
    if mode == "fast":  # fast mode keeps input positions: each corner is one of its card's corners
        for corner in range(3):
            d = np.linalg.norm(result.vertices[out[:, corner]][:, None] -
                               vertices.reshape(cards, 4, 3)[source_card], axis=2).min(axis=1)
            assert d.max() == 0.0


@pytest.mark.parametrize("mode", MODES)
def test_cards_beside_a_torus_meet_the_target_together(mode):
    """500 cards beside a 20,000-triangle torus at 30 %: every card stays (one or two triangles)
    and the scene meets its vertex target within the budget's tolerance."""
    torus_v, torus_f = meshgen.bumpy_torus(20000)
    card_v, card_f = shape_families.foliage_cards(1000)
    vertices = np.vstack([torus_v, card_v])
    faces = np.vstack([torus_f, card_f + len(torus_v)]).astype(np.int32)
    result = Mesh(vertices, faces).decimate(ratio=0.3, mode=mode, seed=1)
    comp = components(len(result.vertices), result.triangles)
    sizes = np.sort(np.bincount(comp[np.asarray(result.triangles)[:, 0]]))
    assert len(sizes) == 501 and sizes[0] >= 1 and sizes[-2] <= 2
    target = int(0.3 * len(vertices))
    assert abs(result.num_vertices - target) <= 0.05 * target


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("ratio", [0.02, 0.2])
def test_hair_strips_keep_every_strip_a_disc(mode, ratio):
    vertices, faces = shape_families.hair_strips(3200)
    strips = len(faces) // 16
    result = Mesh(vertices, faces).decimate(ratio=ratio, mode=mode, seed=1)
    found = invariants(len(result.vertices), result.triangles)
    assert len(found) == strips
    assert all(item == (1, 1, True, True) for item in found)  # each a disc: chi 1, one boundary loop
    target = max(3 * strips, int(ratio * len(vertices)))
    assert result.num_vertices <= 1.1 * target
    if 3 * strips > ratio * len(vertices):  # the strips' floor: the detail names them, not holes to fill
        missed = result.stats.target_missed
        assert missed.reason == "topology" and missed.detail == (
            f"the input's {strips:,} separate open pieces (strips, cards, parts) keep at least a triangle each")


@pytest.mark.parametrize("mode", MODES)
def test_closed_pieces_below_their_floor_are_named(mode):
    """Twenty spheres (shape_families.many_spheres) asked for 20 vertices: each closed piece keeps
    at least 4, and the detail counts the pieces (counted here by tests/reference.py)."""
    vertices, faces = shape_families.many_spheres(20 * 1280)
    pieces = int(components(len(vertices), faces).max()) + 1
    result = Mesh(vertices, faces).decimate(target_vertices=20, mode=mode, seed=1)
    missed = result.stats.target_missed
    assert pieces == 20 and missed.got >= 4 * pieces and missed.reason == "topology"
    assert missed.detail.startswith(f"the input's {pieces:,} separate pieces keep at least a few vertices each")
