"""Loose triangles: an unwelded mesh (each triangle its own piece, every corner its own vertex)
and a welded surface beside such pieces. Each piece keeps its one triangle, so the result keeps
every loose triangle as it is, the rest is decimated, and a missed target says why in words
that name the cause. Positions and pieces are compared with numpy, independently of the engine.
"""

import numpy as np
import pytest

import meshgen
from topstoc.core import Mesh


def unwelded(vertices, triangles):
    """Every triangle its own piece: its three corners copied out as vertices of their own."""
    v = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles).ravel()]
    return v, np.arange(len(v), dtype=np.int32).reshape(-1, 3)


def corner_rows(vertices, triangles):
    """Each triangle as the sorted rows of its corners' positions (a set independent of ids)."""
    p = np.asarray(vertices)[np.asarray(triangles)]
    return {tuple(map(tuple, sorted(map(tuple, tri)))) for tri in p}


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_an_unwelded_mesh_comes_back_whole_and_says_why(mode):
    v, t = unwelded(*meshgen.icosphere(4))
    r = Mesh(v, t).decimate(target_triangles=len(t) // 10, seed=0, mode=mode)
    assert len(r.triangles) == len(t)
    assert corner_rows(r.vertices, r.triangles) == corner_rows(v, t)
    assert r.stats.loose_triangles == len(t)
    missed = r.stats.target_missed
    assert missed.reason == "topology"
    assert f"{len(t):,} of the result's {len(t):,} triangles are loose pieces" in missed.detail
    assert "Merge by Distance" in missed.detail
    assert r.stats.refine_collapses == 0


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_loose_triangles_stay_beside_a_decimated_surface(mode):
    sv, st = meshgen.icosphere(4)  # 2,562 vertices, 5,120 triangles
    lv, lt = unwelded(*meshgen.icosphere(3))  # 1,280 loose triangles, moved aside
    lv = lv + np.array([3.0, 0.0, 0.0])
    v = np.vstack([sv, lv])
    t = np.vstack([st, lt + len(sv)]).astype(np.int32)
    target = 1280 + 500
    r = Mesh(v, t).decimate(target_triangles=target, seed=0, mode=mode)
    assert corner_rows(lv, lt) <= corner_rows(r.vertices, r.triangles)  # every loose one, as it was
    assert r.stats.loose_triangles == len(lt)
    sphere = r.triangles[(r.vertices[r.triangles][:, :, 0] < 1.5).all(axis=1)]
    assert 0 < len(sphere) <= 1.02 * 500  # the welded sphere took the rest of the budget
    assert r.stats.target_missed is None
