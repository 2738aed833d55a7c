"""Live Preview status text: a fast-mode draft below a high-genus mesh's topology floor is the
plain first pass (stats.collapses_skipped), while the rested result collapses it further; the
header says so while dragging, and no longer once the drag rests.

The thresholds are set instead of relying on the machine's speed (as in test_preview_rest.py):
DIRECT_SECONDS 0 makes the drag show drafts, REST_SECONDS a day and then 0 holds and brings the rest."""

from types import SimpleNamespace

import bpy

import meshgen
from helpers import Params, make_object, wait_for

DAY = 86400.0
CLAUSE = "above target: the rested result collapses further"


def shown_until(session, condition):
    return wait_for(lambda: (session.poll(), condition())[1])


def header(ts, session):
    """The text the operator's header and status bar show for the session's result."""
    texts = []
    operator = SimpleNamespace(session=session, quality="FAST", started=0.0, ratio=session.ratio,
                               obj_name="Grid", _status=lambda context, text: texts.append(text))
    ts.blender.operators.preview.TOPSTOC_OT_preview._header(operator, bpy.context)
    return texts[-1]


def test_a_draft_above_its_target_says_the_rest_collapses_further(ts, scene, monkeypatch):
    preview = ts.blender.preview.session
    ts.blender.preview.cache.prepared_meshes.clear()
    monkeypatch.setattr(preview, "SPECULATE", False)
    monkeypatch.setattr(preview, "DIRECT_SECONDS", 0.0)
    monkeypatch.setattr(preview, "REST_SECONDS", DAY)
    grid = make_object("Grid", *meshgen.genus_grid(4, 4, scale=(2, 2, 2)))  # genus 16, 890 vertices
    session = preview.PreviewSession(bpy.context, grid, Params(quality="FAST", seed=0), ratio=0.05)
    try:
        assert shown_until(session, lambda: session.ratio == 0.05)
        session.request(0.01)  # 9 vertices asked: far below the genus' floor
        assert shown_until(session, lambda: session.ratio == 0.01 and not session.busy)
        assert not session.final and session.result.stats.collapses_skipped
        draft_vertices, draft_text = session.result.num_vertices, header(ts, session)
        assert f"{draft_vertices:,} vertices" in draft_text and CLAUSE in draft_text, draft_text
        monkeypatch.setattr(preview, "REST_SECONDS", 0.0)
        assert shown_until(session, lambda: session.final)
        rested_text = header(ts, session)
        assert not session.result.stats.collapses_skipped and session.result.num_vertices < draft_vertices
        assert f"{session.result.num_vertices:,} vertices" in rested_text and "(Fast)" in rested_text
        assert CLAUSE not in rested_text and "draft" not in rested_text, rested_text
    finally:
        session.close()
