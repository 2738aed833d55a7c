"""Seam and sharp flags of a written result: an output edge is flagged exactly when it joins two
kept vertices along a flagged input curve (one flagged edge, or a chain of them whose inner
vertices were dropped), recomputed here by a search on the input's own flags; the flagged curves
survive one for one (Fast and Quality, new object, in place and the Live Preview)."""

from collections import defaultdict, deque

import bpy
import numpy as np
import pytest

from helpers import Params, positions

FLAGS = ("use_seam", "use_edge_sharp")


def edge_pairs(mesh):
    pairs = np.empty(2 * len(mesh.edges), dtype=np.int32)
    mesh.edges.foreach_get("vertices", pairs)
    return pairs.reshape(-1, 2)


def edge_flag(mesh, flag):
    """The flag of every edge, read through MeshEdge (not through the add-on)."""
    values = np.zeros(len(mesh.edges), dtype=bool)
    mesh.edges.foreach_get(flag, values)
    return values


def expected_flags(input_pairs, output_pairs, kept, moved):
    """Per output edge, by breadth-first search from its first kept vertex along flagged input
    edges, never through a kept input vertex, reaching its second one."""
    kept_set = {int(k) for k, m in zip(kept, moved) if not m}
    neighbours = defaultdict(set)
    for p, q in input_pairs.tolist():
        neighbours[p].add(q)
        neighbours[q].add(p)
    out = []
    for a, b in output_pairs.tolist():
        if moved[a] or moved[b]:
            out.append(False)
            continue
        start, goal = int(kept[a]), int(kept[b])
        seen, queue, found = {start}, deque([start]), False
        while queue and not found:
            x = queue.popleft()
            for y in neighbours[x]:
                found = found or y == goal
                if y not in seen and y not in kept_set:
                    seen.add(y)
                    queue.append(y)
        out.append(found)
    return np.array(out, dtype=bool)


def curve_count(pairs):
    """Curves of an edge graph: chains between vertices of degree other than 2, and closed loops."""
    degree = defaultdict(int)
    neighbours = defaultdict(list)
    for p, q in pairs.tolist():
        degree[p] += 1
        degree[q] += 1
        neighbours[p].append(q)
        neighbours[q].append(p)
    open_chains = sum(d for d in degree.values() if d != 2) // 2
    seen, loops = set(), 0
    for start in degree:
        if start in seen:
            continue
        component, stack = [], [start]
        seen.add(start)
        while stack:
            x = stack.pop()
            component.append(x)
            for y in neighbours[x]:
                if y not in seen:
                    seen.add(y)
                    stack.append(y)
        loops += all(degree[x] == 2 for x in component)
    return open_chains + loops


@pytest.fixture
def flagged_sphere(scene):
    """A UV sphere with seams on three meridians (the poles are junctions of three) and sharp edges
    on two latitude rings (closed loops), both kept as borders."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=36, ring_count=18)
    obj = bpy.context.object
    mesh = obj.data
    v = positions(mesh).astype(float)
    e = edge_pairs(mesh)
    pole = np.hypot(v[:, 0], v[:, 1]) < 1e-5
    angle = np.round(np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360, 3)
    meridians = np.unique(angle[~pole])[[1, 13, 25]]
    on_meridian = [pole | (np.abs((angle - a + 180) % 360 - 180) < 1e-2) for a in meridians]
    seams = np.zeros(len(e), dtype=bool)
    for on in on_meridian:
        seams |= on[e].all(axis=1)
    sharp = np.zeros(len(e), dtype=bool)
    for z in np.unique(np.round(v[~pole, 2], 5))[[4, 11]]:
        sharp |= (np.abs(v[e][:, :, 2] - z) < 1e-5).all(axis=1)
    mesh.edges.foreach_set("use_seam", seams)
    mesh.edges.foreach_set("use_edge_sharp", sharp)
    obj.topstoc.use_uv_seams = True
    obj.topstoc.use_sharp = True
    assert seams.sum() == 3 * 18 and sharp.sum() == 2 * 36
    assert curve_count(e[seams]) == 3 and curve_count(e[sharp]) == 2
    return obj


def check_flags(source, mesh, kept, moved):
    """Every output edge flagged iff the rule holds; the curves survive one for one."""
    out_pairs = edge_pairs(mesh)
    figures = {}
    for flag in FLAGS:
        input_pairs = edge_pairs(source)[edge_flag(source, flag)]
        got = edge_flag(mesh, flag)
        want = expected_flags(input_pairs, out_pairs, kept, moved)
        np.testing.assert_array_equal(got, want, err_msg=flag)
        assert 0 < got.sum() < len(input_pairs), flag
        assert curve_count(out_pairs[got]) == curve_count(input_pairs), flag
        figures[flag] = (len(input_pairs), int(got.sum()))
    return figures


@pytest.mark.parametrize("quality", ["FAST", "QUALITY"])
def test_flags_follow_the_flagged_curves(ts, flagged_sphere, quality):
    obj = flagged_sphere
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.15, seed=4, quality=quality))
    out = ts.blender.decimation.pipeline.write_output(run)
    kept = np.asarray(run.result.kept)
    moved = np.any(positions(out.data) != positions(obj.data)[kept], axis=1)
    assert (quality == "QUALITY") == bool(moved.any())  # the quality mode moved some vertices
    figures = check_flags(obj.data, out.data, kept, moved)
    if bpy.app.version >= (4, 0, 0):  # Blender's own names and types, so its tools see them
        seam = ".uv_seam" if bpy.app.version < (4, 5, 0) else "uv_seam"
        for name in (seam, "sharp_edge"):
            assert (out.data.attributes[name].domain, out.data.attributes[name].data_type) == ("EDGE", "BOOLEAN")
    assert out.data.validate() is False  # nothing for Blender to correct
    print(quality, "flagged edges in -> out:", figures)


def test_in_place_result_keeps_the_flags(ts, flagged_sphere):
    obj = flagged_sphere
    source = obj.data.copy()
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.2, seed=1))
    ts.blender.decimation.pipeline.write_output(run, mode="IN_PLACE")
    assert len(obj.data.vertices) == run.result.num_vertices
    check_flags(source, obj.data, np.asarray(run.result.kept), np.zeros(run.result.num_vertices, dtype=bool))
    bpy.data.meshes.remove(source)


def test_live_preview_shows_the_flags(ts, flagged_sphere):
    obj = flagged_sphere
    session = ts.blender.preview.session.PreviewSession(bpy.context, obj, Params(quality="FAST", seed=2), ratio=None)
    try:
        session.update(0.2)
        kept = np.asarray(session.result.kept)
        check_flags(obj.data, session.mesh, kept, np.zeros(len(kept), dtype=bool))
    finally:
        session.close()


def test_a_mesh_without_flags_gets_none(ts, scene):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=36, ring_count=18)
    obj = bpy.context.object
    obj.topstoc.use_sharp = True
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.15, seed=4))
    mesh = ts.blender.decimation.pipeline.write_output(run).data
    for flag in FLAGS:
        assert not edge_flag(mesh, flag).any()
    names = {attribute.name for attribute in mesh.attributes}
    assert not names & {".uv_seam", "uv_seam", "sharp_edge"}


def test_flags_not_used_as_borders_follow_the_rule(ts, flagged_sphere):
    """With Keep UV Seams and Keep Sharp Edges off the curves are not sampled as curves: an output
    edge is still flagged exactly where the rule finds a chain (here: few or none)."""
    obj = flagged_sphere
    obj.topstoc.use_uv_seams = obj.topstoc.use_sharp = False
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, Params(ratio=0.15, seed=4, quality="QUALITY"))
    out = ts.blender.decimation.pipeline.write_output(run).data
    kept = np.asarray(run.result.kept)
    moved = np.any(positions(out) != positions(obj.data)[kept], axis=1)
    out_pairs = edge_pairs(out)
    for flag in FLAGS:
        want = expected_flags(edge_pairs(obj.data)[edge_flag(obj.data, flag)], out_pairs, kept, moved)
        np.testing.assert_array_equal(edge_flag(out, flag), want, err_msg=flag)
        print(flag, "not borders: flagged out", int(want.sum()))
