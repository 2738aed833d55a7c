"""Metrics panel data inside Blender: Hausdorff figures and aspect ratio against independent
computations, error colours (overlay arrays and colour attribute), samples and clusters of the
last decimation, the turntable path, bad input, and no gpu in background mode."""

import importlib
import math

import bpy
import numpy as np
import pytest

import meshgen
from helpers import make_object, positions, select_only


@pytest.fixture
def mods(ts):
    names = {"metrics": "blender.analysis.metrics", "overlay_data": "blender.ui.overlay_data",
             "overlays": "blender.ui.overlays", "operators": "blender.operators.metrics", "panel": "blender.ui.metrics",
             "colors": "core.support.colors", "watch": "blender.preview.watch"}
    return type("Mods", (), {key: importlib.import_module(f"{ts.__name__}.{name}") for key, name in names.items()})


def point_triangle_distance(p, a, b, c):
    """Distance of points p (k, 3) to triangle abc, brute force over the region tests (Ericson)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ap @ ab, ap @ ac
    bp = p - b
    d3, d4 = bp @ ab, bp @ ac
    cp = p - c
    d5, d6 = cp @ ab, cp @ ac
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    denom = np.where(va + vb + vc == 0, 1e-300, va + vb + vc)
    v, w = vb / denom, vc / denom
    closest = a + np.outer(v, ab) + np.outer(w, ac)
    def edge(x, y, px):
        t = np.clip(((px - x) @ (y - x)) / max((y - x) @ (y - x), 1e-300), 0, 1)
        return x + np.outer(t, y - x)
    candidates = [closest, edge(a, b, p), edge(b, c, p), edge(a, c, p)]
    inside = (va >= 0) & (vb >= 0) & (vc >= 0)
    dist = np.stack([np.linalg.norm(p - q, axis=1) for q in candidates[1:]]).min(axis=0)
    return np.where(inside, np.linalg.norm(p - closest, axis=1), dist)


def surface_distance(points, vertices, triangles):
    best = np.full(len(points), np.inf)
    for t in triangles:
        best = np.minimum(best, point_triangle_distance(points, *vertices[t]))
    return best


def aspect_ratio(vertices, triangles):
    """Thesis eq. 4.2, written out."""
    e = np.stack([np.linalg.norm(vertices[triangles[:, i]] - vertices[triangles[:, (i + 1) % 3]], axis=1)
                  for i in range(3)], axis=1)
    s = e.sum(axis=1) / 2
    return e.prod(axis=1) / (8 * (s - e[:, 0]) * (s - e[:, 1]) * (s - e[:, 2]))


@pytest.fixture
def decimated(ts, scene):
    obj = make_object("Ring", *meshgen.torus(40, 16))
    obj.location = (3, 0, 0)
    obj.rotation_euler = (0.3, 0.2, 0.1)
    # Fast mode: output vertices are input vertices, which the per-face check below relies on
    # (a face's sampled maximum bounds its interior only when its corners lie on the original).
    assert bpy.ops.topstoc.guided_decimate(ratio=0.12, seed=4, quality="FAST") == {"FINISHED"}
    out = bpy.data.objects["Ring_TopStoc"]
    out.location = (10, 0, 0)  # moved next to the original: still compared in its own frame
    out.topstoc.metrics.samples = 20000
    select_only(out)
    return obj, out


def test_measure_stores_figures_that_match_independent_computations(mods, decimated):
    original, out = decimated
    assert bpy.ops.topstoc.measure() == {"FINISHED"}
    m = out.topstoc.metrics
    assert m.state == "OK" and m.reference == original
    v, t = positions(original.data).astype(float), np.array([p.vertices[:] for p in original.data.polygons])
    w, u = positions(out.data).astype(float), np.array([p.vertices[:] for p in out.data.polygons])
    assert m.diagonal == pytest.approx(np.linalg.norm(v.max(0) - v.min(0)), rel=1e-6)
    # the forward distance samples every original vertex: its max is at least their brute-force max
    vertex_max = surface_distance(v, w, u).max()
    assert vertex_max - 1e-9 <= m.forward_max <= vertex_max * 1.5 + 1e-9
    assert m.symmetric_max == pytest.approx(max(m.forward_max, m.backward_max))
    assert m.symmetric_mean == pytest.approx(max(m.forward_mean, m.backward_mean))
    assert m.forward_mean <= m.forward_rms <= m.forward_max
    ar = aspect_ratio(w, u)
    assert m.aspect_mean == pytest.approx(ar.mean(), rel=1e-6) and m.aspect_max == pytest.approx(ar.max(), rel=1e-6)  # float32 properties
    figures = mods.metrics.figures(out)
    assert figures["backward_percent"]["rms"] == pytest.approx(100 * m.backward_rms / m.diagonal)
    errors = mods.metrics.face_errors(out)
    assert errors.shape == (len(u),) and errors.max() == pytest.approx(m.backward_max)
    # per-face error of a few triangles: their vertices lie on the original (subsampling), and
    # densely sampled interior points are never farther than the stored face maximum
    for j in np.argsort(errors)[-3:]:
        a, b, c = w[u[j]]
        bary = np.random.default_rng(j).dirichlet((1, 1, 1), 300)
        points = bary @ np.stack([a, b, c])
        assert surface_distance(points, v, t).max() <= errors[j] * 1.02 + 1e-9
    assert mods.metrics.is_current(out)
    co = positions(out.data)
    co[0] += 0.05
    out.data.vertices.foreach_set("co", co.ravel())
    out.data.update()
    mods.watch.bump(out)
    assert not mods.metrics.is_current(out)  # the figures no longer describe the mesh


def test_error_overlay_and_colour_attribute(mods, decimated):
    original, out = decimated
    assert bpy.ops.topstoc.measure() == {"FINISHED"}
    show = bpy.context.scene.topstoc.overlays
    assert mods.overlay_data.error_primitives(out, show) == []        # off by default
    show.show_error = True
    show.error_scale = 0.0
    (primitive,) = mods.overlay_data.error_primitives(out, show)
    mesh = out.data
    mesh.calc_loop_triangles()
    corners = np.array([mesh.vertices[i].co[:] for tri in mesh.loop_triangles for i in tri.vertices])
    np.testing.assert_allclose(primitive.positions, corners, atol=1e-6)  # object space: the transform is the GPU's
    errors = mods.metrics.face_errors(out)
    expected = mods.colors.error_colors(errors, errors.max())
    np.testing.assert_allclose(primitive.colors[::3], expected, atol=1e-5)  # the scale is a float32 property
    show.error_scale = 1.0                                             # red at 1 % of the diagonal
    (primitive,) = mods.overlay_data.error_primitives(out, show)
    np.testing.assert_allclose(primitive.colors[::3],
                               mods.colors.error_colors(errors, 0.01 * out.topstoc.metrics.diagonal), atol=1e-5)
    assert bpy.ops.topstoc.write_error_colors() == {"FINISHED"}
    attribute = mesh.color_attributes["TopStoc Error"]
    assert attribute.domain == "CORNER" and mesh.color_attributes.active_color.name == "TopStoc Error"
    values = np.empty(4 * len(mesh.loops), dtype=np.float32)
    attribute.data.foreach_get("color", values)
    srgb = np.where(values.reshape(-1, 4)[:, :3] <= 0.0031308, values.reshape(-1, 4)[:, :3] * 12.92,
                    1.055 * np.clip(values.reshape(-1, 4)[:, :3], 0, None) ** (1 / 2.4) - 0.055)
    loop_polygon = np.repeat(np.arange(len(mesh.polygons)), [p.loop_total for p in mesh.polygons])
    polygon_error = np.zeros(len(mesh.polygons))
    for tri, e in zip(mesh.loop_triangles, errors):
        polygon_error[tri.polygon_index] = max(polygon_error[tri.polygon_index], e)
    want = mods.colors.error_colors(polygon_error, 0.01 * out.topstoc.metrics.diagonal)[loop_polygon, :3]
    np.testing.assert_allclose(srgb, want, atol=2e-3)


def test_clusters_and_samples_of_the_last_decimation(mods, ts, scene):
    obj = make_object("Ball", *meshgen.icosphere(3))
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, type("P", (), dict(
        target_mode="RATIO", ratio=0.1, seed=5, adaptivity=0.5, density="off", placement="subsample", refine=0))())
    ts.blender.decimation.pipeline.store_samples(run)
    show = bpy.context.scene.topstoc.overlays
    show.show_samples = show.show_clusters = True
    samples, labels = mods.overlay_data.last_decimation(obj)
    np.testing.assert_array_equal(labels, run.result.labels)
    prims = {p.name: p for p in mods.overlay_data.decimation_primitives(obj, show)}
    np.testing.assert_allclose(prims["samples"].positions, positions(obj.data)[samples])
    # thesis fig. 4.1: the red faces (corners in three clusters) are exactly the output triangles
    triangles = np.array([p.vertices[:] for p in obj.data.polygons])
    red = np.all(np.isclose(prims["clusters"].colors[::3], mods.colors.CLUSTER_CORNER), axis=1)
    red_triples = {tuple(sorted(labels[f])) for f in triangles[red]}
    assert red_triples == {tuple(sorted(f)) for f in run.result.triangles.tolist()}
    # a changed mesh shows nothing rather than stale clusters
    co = positions(obj.data)
    co[3] += 0.1
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    mods.watch.bump(obj)
    assert mods.overlay_data.decimation_primitives(obj, show) == []


def test_bad_input_is_reported_without_trace(mods, ts, scene):
    lonely = make_object("Lonely", *meshgen.icosphere(1))
    with pytest.raises(RuntimeError, match="no original to compare with"):
        bpy.ops.topstoc.measure()
    m = lonely.topstoc.metrics
    assert m.state == "ERROR" and "no original" in m.message
    empty = make_object("Empty", np.zeros((3, 3)), [])
    lonely.topstoc.metrics.reference = empty
    select_only(lonely)
    with pytest.raises(RuntimeError, match="has no faces"):
        bpy.ops.topstoc.measure()
    assert len(lonely.data.vertices) == 42  # nothing lost
    assert not bpy.ops.topstoc.write_error_colors.poll()
    with pytest.raises(mods.metrics.MetricsError, match="no up-to-date error measurement"):
        mods.metrics.write_error_colors(lonely)


def test_turntable_spirals_twice_upwards(mods):
    spiral = mods.operators.spiral
    low, high = math.radians(-15), math.radians(55)
    assert spiral(0.0) == pytest.approx((0.0, low))
    assert spiral(1.0) == pytest.approx((4 * math.pi, high))
    path = [spiral(t / 100) for t in range(101)]
    assert all(b[0] >= a[0] and b[1] >= a[1] for a, b in zip(path, path[1:]))  # always onwards and upwards
    assert spiral(0.5)[0] == pytest.approx(2 * math.pi)  # one turn at half time


def test_turntable_view_rotation_looks_at_the_pivot(mods):
    from mathutils import Vector

    for azimuth, elevation in ((0.0, 0.0), (1.0, 0.5), (4.0, -0.3)):
        forward = mods.operators.view_rotation(azimuth, elevation) @ Vector((0, 0, -1))  # views look down -Z
        eye = Vector((math.sin(azimuth) * math.cos(elevation), -math.cos(azimuth) * math.cos(elevation),
                      math.sin(elevation)))  # azimuth 0 = the front view, from -Y
        assert (forward + eye).length < 1e-6, (azimuth, elevation, forward, eye)


def test_no_gpu_in_background_mode(mods, decimated):
    assert bpy.app.background
    assert mods.overlays._handlers == {}
    show = bpy.context.scene.topstoc.overlays
    show.show_error = show.show_samples = show.show_clusters = True
    bpy.ops.topstoc.measure()
    mods.overlay_data.object_primitives(decimated[1], show)
    assert mods.overlays._shaders == {} and mods.overlays._batches == {}


def test_metrics_panel_rows(mods, decimated):
    assert bpy.ops.topstoc.measure() == {"FINISHED"}
    out = decimated[1]
    rows = mods.panel.distance_rows(out)
    m = out.topstoc.metrics
    assert [label for label, _ in rows][0] == "Symmetric"
    name, absolute, percent = rows[2][1][0]
    assert name == "Max" and float(absolute) == pytest.approx(m.backward_max, rel=1e-3)
    assert float(percent.rstrip(" %")) == pytest.approx(100 * m.backward_max / m.diagonal, rel=1e-2)


def test_metrics_panels_draw_measured_and_failed_states(mods, decimated):
    from test_registration import fake_panel

    out = decimated[1]
    seen = set()
    for state in ("NONE", "OK", "ERROR"):
        if state == "OK":
            assert bpy.ops.topstoc.measure() == {"FINISHED"}
        if state == "ERROR":
            out.topstoc.metrics.state, out.topstoc.metrics.message = "ERROR", "something clear"
        for cls in mods.panel.CLASSES:
            fake = fake_panel(cls, seen)
            if hasattr(cls, "draw_header"):
                cls.draw_header(fake, bpy.context)
            cls.draw(fake, bpy.context)
    assert {"topstoc.measure", "topstoc.write_error_colors", "topstoc.turntable", "reference", "samples",
            "show_error", "error_scale"} <= seen


def test_objects_shown_together_share_one_error_scale(mods, decimated):
    """Issue 38: each object was coloured on its own scale (red at its own largest error) under one
    legend. Two results of one original, at 12 % and 40 %: one scale, the larger error's, for both;
    the colour attribute written uses it too."""
    original, coarse = decimated
    assert bpy.ops.topstoc.measure() == {"FINISHED"}
    select_only(original)
    assert bpy.ops.topstoc.guided_decimate(ratio=0.4, seed=4, quality="FAST") == {"FINISHED"}
    fine = bpy.context.active_object
    fine.topstoc.metrics.samples = 20000
    assert bpy.ops.topstoc.measure() == {"FINISHED"}
    show = bpy.context.scene.topstoc.overlays
    show.show_error, show.error_scale = True, 0.0
    m_coarse, m_fine = coarse.topstoc.metrics, fine.topstoc.metrics
    assert m_coarse.backward_max > 1.5 * m_fine.backward_max and m_coarse.diagonal == pytest.approx(m_fine.diagonal)
    shared = mods.metrics.shared_error_percent([original, coarse, fine], 0.0)
    assert shared == pytest.approx(100 * m_coarse.backward_max / m_coarse.diagonal)
    (primitive,) = mods.overlay_data.error_primitives(fine, show, shared)
    red_at = m_coarse.backward_max * m_fine.diagonal / m_coarse.diagonal
    expected = mods.colors.error_colors(mods.metrics.face_errors(fine), red_at)
    np.testing.assert_allclose(primitive.colors[::3], expected, atol=1e-5)
    own = mods.colors.error_colors(mods.metrics.face_errors(fine), m_fine.backward_max)
    assert not np.allclose(primitive.colors[::3], own, atol=1e-3)  # not its own scale
    assert mods.metrics.shared_error_percent([coarse, fine], 2.5) == 2.5  # a scale set by the user holds
    select_only(fine)
    assert bpy.ops.topstoc.write_error_colors() == {"FINISHED"}
    mesh = fine.data
    written = np.empty(4 * len(mesh.loops), dtype=np.float32)
    mesh.color_attributes["TopStoc Error"].data.foreach_get("color", written)
    first_loop = np.array([p.loop_start for p in mesh.polygons])
    fine_errors = mods.metrics.face_errors(fine)
    mesh.calc_loop_triangles()
    polygon_error = np.zeros(len(mesh.polygons))
    np.maximum.at(polygon_error, [t.polygon_index for t in mesh.loop_triangles], fine_errors)
    srgb = mods.colors.error_colors(polygon_error, red_at)
    linear = written.reshape(-1, 4)[first_loop]
    np.testing.assert_allclose(linear[:, :3], mods.metrics.srgb_to_linear(srgb[:, :3]), atol=1e-4)
