"""Samples restore identically; multiview and LOD chains; the live-preview update path."""

import bpy
import numpy as np
import pytest

import meshgen
from helpers import Params, make_object, polygons, positions, select_only


def output_geometry(obj):
    return positions(obj.data).tolist(), polygons(obj.data)


def test_samples_restore_identically(ts, scene):
    obj = make_object("Knot", *meshgen.torus(48, 16))
    obj.topstoc.use_sharp = True
    bpy.ops.topstoc.guided_decimate(ratio=0.15, seed=7, adaptivity=0.8, density="adaptive")
    first = bpy.data.objects["Knot_TopStoc"]
    select_only(obj)
    assert bpy.ops.topstoc.save_samples(name="Keep") == {"FINISHED"}
    bpy.ops.topstoc.guided_decimate(ratio=0.3, seed=1)            # another run replaces "Last"
    select_only(obj)
    assert bpy.ops.topstoc.restore_samples(name="Keep") == {"FINISHED"}
    restored = bpy.data.objects["Knot_Keep"]
    assert output_geometry(restored) == output_geometry(first)
    saved = obj.topstoc.sample_sets["Keep"]
    assert saved.vertices_out == len(first.data.vertices)
    assert '"seed": 7' in saved.parameters


def test_restore_refuses_a_changed_mesh(ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(3))
    bpy.ops.topstoc.guided_decimate(ratio=0.2)
    select_only(obj)
    co = positions(obj.data)
    co[5] += 0.01
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    with pytest.raises(RuntimeError, match="changed since the samples"):
        bpy.ops.topstoc.restore_samples(name="Last")


def test_multiview_variants(ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(4))
    assert bpy.ops.topstoc.multiview(ratio=0.1, count=5, variance=0.5, seed=2) == {"FINISHED"}
    collection = bpy.data.collections["Ball Multiview"]
    names = sorted(o.name for o in collection.objects)
    assert names == [f"Ball_MV{i}" for i in range(1, 6)]
    counts = [len(bpy.data.objects[n].data.vertices) for n in names]
    n = len(obj.data.vertices)
    expected = [round(n * 0.1 * (1 + 0.5 * t)) for t in np.linspace(-1, 1, 5)]
    for got, want in zip(counts, expected):
        assert abs(got - want) <= max(2, 0.01 * want)
    xs = [bpy.data.objects[name].location.x for name in names]
    assert all(b > a for a, b in zip(xs, xs[1:])) and xs[0] > obj.location.x


def test_lod_chain(ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(4))
    assert bpy.ops.topstoc.lod_chain(ratios="1.0, 0.5, 0.2, 0.05") == {"FINISHED"}
    lods = [bpy.data.objects[f"Ball_LOD{i}"] for i in range(4)]
    assert {o.name for o in bpy.data.collections["Ball LODs"].objects} == {o.name for o in lods}
    counts = [len(o.data.vertices) for o in lods]
    assert counts[0] == len(obj.data.vertices)
    assert counts == sorted(counts, reverse=True)
    assert abs(counts[2] - 0.2 * counts[0]) <= 0.01 * counts[0]
    with pytest.raises(RuntimeError, match="LOD ratios"):
        bpy.ops.topstoc.lod_chain(ratios="1, 2")


def test_preview_session(ts, scene, monkeypatch):
    obj = make_object("Donut", *meshgen.torus(64, 32))
    from helpers import Params

    monkeypatch.setattr(ts.blender.preview.session, "SPECULATE", False)  # drafts until the drag rests

    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, Params(seed=4, quality="QUALITY"))
    assert not obj.hide_get() and session.preview is None  # nothing changes before a result shows
    for ratio in (0.5, 0.1, 0.02):
        session.update(ratio)
        expected = session.prepared.mesh.decimate(ratio=ratio, seed=4, mode="fast")
        assert len(session.mesh.vertices) == expected.num_vertices
        assert len(session.mesh.polygons) == expected.num_triangles
        assert obj.hide_get()
    # Asynchronous path: only the latest request is computed.
    session.request(0.3)
    session.request(0.05)
    import time

    for _ in range(2000):  # at most 10 s
        session.poll()
        time.sleep(0.005)
        if not session.busy and session.ratio == 0.05:
            break
    assert session.ratio == 0.05
    # the worker went from 0.3 to 0.05 on its own: nothing is left to show
    assert not session.busy and not session.poll()
    # A quick drag: two workers may run at once, but what is shown follows the requests' order
    # and ends on the last one.
    drag = [0.4, 0.3, 0.25, 0.2, 0.15, 0.12, 0.1, 0.08]
    shown = []
    for ratio in drag:
        session.request(ratio)
        if session.poll():
            shown.append(session.ratio)
        time.sleep(0.002)
    for _ in range(2000):
        if session.poll():
            shown.append(session.ratio)
        if not session.busy:
            break
        time.sleep(0.005)
    assert shown and shown[-1] == drag[-1]
    assert [drag.index(r) for r in shown] == sorted(drag.index(r) for r in shown)
    assert len(set(shown)) == len(shown)
    expected = session.prepared.mesh.decimate(ratio=drag[-1], seed=4, mode="fast")
    assert len(session.mesh.vertices) == expected.num_vertices and not session.final
    # the drag pauses: the quality result replaces the fast one
    for _ in range(4000):
        session.poll()
        if session.final:
            break
        time.sleep(0.005)
    assert session.final and session.ratio == drag[-1]
    quality = session.prepared.mesh.decimate(ratio=drag[-1], seed=4)
    np.testing.assert_array_equal(session.result.vertices, quality.vertices)
    assert len(session.mesh.vertices) == quality.num_vertices
    # an engine error in the worker surfaces on the main thread, at the next poll
    session.options = dict(session.options, placement="no such placement")
    session.drag_options = dict(session.drag_options, placement="no such placement")
    session.request(0.2)
    with pytest.raises(ValueError, match="placement"):
        for _ in range(2000):
            session.poll()
            time.sleep(0.005)
    assert session.ratio == drag[-1]
    name = session.preview.name
    session.close()
    assert not obj.hide_get()
    assert name not in bpy.data.objects


def test_refined_decimation_keeps_uvs_and_restores(ts, scene):
    obj = make_object("Knot", *meshgen.torus(48, 16))
    obj.data.uv_layers.new(name="UVMap")
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.uv.smart_project(island_margin=0.02)  # several islands: seams the refinement must keep
    bpy.ops.object.mode_set(mode="OBJECT")
    obj.topstoc.use_uv_seams = True
    plain_run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.1, seed=3))
    assert bpy.ops.topstoc.guided_decimate(ratio=0.1, seed=3, quality="CUSTOM", refine=6, placement="subsample") == {"FINISHED"}
    first = bpy.data.objects["Knot_TopStoc"]
    assert len(first.data.vertices) <= max(plain_run.result.num_vertices, plain_run.result.stats.target_vertices)
    # every corner of a vertex that stayed carries exactly a UV its input vertex had; a vertex the
    # collapses moved has one UV (inside an island) within one input triangle's (no island crossed)
    source_uv = np.empty(2 * len(obj.data.loops))
    obj.data.uv_layers["UVMap"].data.foreach_get("uv", source_uv)
    source_uv = source_uv.reshape(-1, 2)
    out_uv = np.empty(2 * len(first.data.loops))
    first.data.uv_layers["UVMap"].data.foreach_get("uv", out_uv)
    out_uv = out_uv.reshape(-1, 2)
    source_corner = np.array([loop.vertex_index for loop in obj.data.loops])
    out_corner = np.array([loop.vertex_index for loop in first.data.loops])
    index = {tuple(p): i for i, p in enumerate(positions(obj.data).tolist())}
    kept = np.array([index.get(tuple(p), -1) for p in positions(first.data).tolist()])
    uvs_at = {}
    for loop, vertex in enumerate(source_corner):
        uvs_at.setdefault(vertex, set()).add(tuple(source_uv[loop]))
    loops = np.array([list(p.loop_indices) for p in obj.data.polygons])
    lo, hi = source_uv[loops].min(axis=1), source_uv[loops].max(axis=1)
    for loop, vertex in enumerate(out_corner):
        if kept[vertex] >= 0:
            assert tuple(out_uv[loop]) in uvs_at[kept[vertex]]
        else:
            assert np.allclose(out_uv[out_corner == vertex], out_uv[loop], atol=1e-6)
            assert np.any(np.all((lo - 1e-6 <= out_uv[loop]) & (out_uv[loop] <= hi + 1e-6), axis=1))
    saved = obj.topstoc.sample_sets["Last"]
    assert '"refine": 6' in saved.parameters and '"refine_vertices": 0' not in saved.parameters
    select_only(obj)
    assert bpy.ops.topstoc.restore_samples(name="Last") == {"FINISHED"}
    assert output_geometry(bpy.data.objects["Knot_Last"]) == output_geometry(first)


def three_sheets(length=40, width=12):
    """Three curved strips sharing their first row: every edge of that spine has three triangles."""
    vertices = [(x, 0.0, 0.0) for x in range(length)]
    triangles = []
    for k in range(3):
        direction = np.array([0.0, np.cos(2 * np.pi * k / 3), np.sin(2 * np.pi * k / 3)])
        rows = [list(range(length))]
        for j in range(1, width):
            rows.append(list(range(len(vertices), len(vertices) + length)))
            vertices += [tuple(j * direction + [x, 0.0, 0.02 * j * j * np.sin(x / 7.0)]) for x in range(length)]
        for j in range(width - 1):
            for x in range(length - 1):
                a, b, c, d = rows[j][x], rows[j][x + 1], rows[j + 1][x], rows[j + 1][x + 1]
                triangles += [(a, b, d), (a, d, c)]
    return np.array(vertices), np.array(triangles, dtype=np.int32)


def test_a_fast_result_collapsed_after_a_stall_restores(ts, scene):
    # Three sheets on one spine: fast mode's repairs stall on the non-manifold edges and
    # half-edge collapses take the result to its target (docs/design.md §2.7); the saved set must
    # replay those collapses, not quality mode's placed ones. (A flipped half of a grid stalled
    # them too, before flipped patches were emitted in one winding.)
    vertices, triangles = three_sheets()
    obj = make_object("Seam", vertices, triangles)
    assert bpy.ops.topstoc.guided_decimate(ratio=0.05, seed=2, quality="FAST") == {"FINISHED"}
    first = bpy.data.objects["Seam_TopStoc"]
    assert len(first.data.vertices) <= 1.05 * 0.05 * len(vertices)  # the stalled pass kept nearly all
    saved = obj.topstoc.sample_sets["Last"]
    assert '"refine_keeps_positions": true' in saved.parameters
    select_only(obj)
    assert bpy.ops.topstoc.restore_samples(name="Last") == {"FINISHED"}
    assert output_geometry(bpy.data.objects["Seam_Last"]) == output_geometry(first)


def test_best_fits_a_large_result_and_restores_it(ts, scene):
    # A result above 1,400 triangles of a mesh collapsed whole: Best fits it to the original
    # (mode "best", the engine's large fit), Quality leaves it where the collapses put it.
    vertices, triangles = meshgen.bumpy_torus(20_000)
    obj = make_object("Bumps", vertices, triangles)
    results = {}
    for quality in ("QUALITY", "BEST"):
        select_only(obj)
        assert bpy.ops.topstoc.guided_decimate(target_mode="TRIANGLES", triangles=3000, seed=2,
                                               quality=quality) == {"FINISHED"}
        results[quality] = bpy.context.active_object
    quality, best = (output_geometry(results[q]) for q in ("QUALITY", "BEST"))
    assert best[1] == quality[1] and best[0] != quality[0]  # the same triangles, moved vertices
    saved = obj.topstoc.sample_sets["Last"]
    assert '"mode": "best"' in saved.parameters
    select_only(obj)
    assert bpy.ops.topstoc.restore_samples(name="Last") == {"FINISHED"}
    assert output_geometry(bpy.data.objects["Bumps_Last"]) == best
