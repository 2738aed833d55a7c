"""Handle and tunnel loops (issue 5): counts, independent homology checks, shortening, errors.

The checks do not trust the production code path: GUDHI computes Betti numbers of the inside
and outside tetrahedral complexes with the loops coned off (tests/homology_check.py), and the
inside/outside labels of the tetrahedra are checked against winding numbers computed here.
"""

import dataclasses

import numpy as np
import pytest

import homology_check as hc
import loop_families
import meshgen
import reference
import topstoc
from reference import read_off

pytestmark = pytest.mark.skipif(hc.gudhi is None, reason="python3-gudhi is not installed")

# (file, genus) of the closed orientable meshes shipped in tests/data/genus_positive.
GENUS_POSITIVE = [
    ("cgal_torus_quad.off", 1), ("cgal_3torus.off", 3), ("cgal_double-torus-example.off", 2),
    ("cgal_eight.off", 2), ("cgal_knot1.off", 1), ("cgal_elephant.off", 3),
    ("cgal_anchor_dense.off", 4), ("cgal_couplingdown.off", 9), ("cgal_turbine.off", 11),
]


def check_component(vertices, triangles, component, field=2):
    """Asserts every property the issue asks of one closed component's loops, independently."""
    vertices, triangles, new_id = only_component(vertices, triangles, component.first_vertex)
    component = renumbered(component, new_id)
    g = component.genus
    assert component.status == "ok"
    assert len(component.handles) == g and len(component.tunnels) == g
    for loop in component.loops:
        assert hc.is_simple_edge_cycle(loop.vertices, triangles)
        assert loop.length == pytest.approx(hc.loop_length(vertices, loop.vertices))
        assert loop.length <= loop.initial_length * (1 + 1e-12)
        assert a_mesh_edge(loop.generator, triangles)
    tets = topstoc.tetrahedralize_surface(vertices, triangles)
    inside = tets["inside"].astype(bool)
    check_sides(vertices, triangles, tets)
    inner, outer = [tets["tets"][inside]], [tets["tets"][~inside]]
    apex = len(tets["points"])
    assert hc.betti(inner, field)[:3] == [1, g, 0]
    assert hc.betti(outer, field)[:3] == [1, g, 1]
    handles = [loop.vertices for loop in component.handles]
    tunnels = [loop.vertices for loop in component.tunnels]
    # Handles bound inside (b1 unchanged) and span H1 outside (b1 drops to 0); tunnels reverse.
    assert hc.coned_b1(inner, handles, apex, field) == g
    assert hc.coned_b1(outer, handles, apex, field) == 0
    assert hc.coned_b1(outer, tunnels, apex, field) == g
    assert hc.coned_b1(inner, tunnels, apex, field) == 0
    # Together they span H1 of the surface.
    assert hc.coned_b1([triangles], handles + tunnels, len(vertices), field) == 0


def only_component(vertices, triangles, first_vertex):
    """The component holding `first_vertex`, renumbered compactly, and the old -> new id map."""
    label = reference.components(len(vertices), triangles)
    keep = np.asarray(triangles)[label[np.asarray(triangles)[:, 0]] == label[first_vertex]]
    used = np.unique(keep)
    new_id = np.full(len(vertices), -1)
    new_id[used] = np.arange(len(used))
    return np.asarray(vertices)[used], new_id[keep].astype(np.int32), new_id


def renumbered(component, new_id):
    def loop(x):
        return dataclasses.replace(x, vertices=new_id[x.vertices], initial_vertices=new_id[x.initial_vertices],
                                   generator=tuple(int(new_id[v]) for v in x.generator))
    return dataclasses.replace(component, handles=tuple(loop(x) for x in component.handles),
                               tunnels=tuple(loop(x) for x in component.tunnels))


def a_mesh_edge(pair, triangles):
    a, b = pair
    t = np.asarray(triangles)
    return bool(np.any(((t == a) | (t == b)).sum(axis=1) == 2))


def check_sides(vertices, triangles, tets, samples=60):
    """Each surface triangle has one inside and one outside tetrahedron; sampled tetrahedra
    lie where the winding number says."""
    t, inside = tets["tets"], tets["inside"].astype(bool)
    faces = np.sort(np.concatenate([t[:, [1, 2, 3]], t[:, [0, 2, 3]], t[:, [0, 1, 3]], t[:, [0, 1, 2]]]), axis=1)
    side = np.concatenate([inside] * 4)
    surface = np.sort(np.asarray(triangles, dtype=np.int64), axis=1)
    key = lambda f: (f[:, 0] * (1 << 21) + f[:, 1]) * (1 << 21) + f[:, 2]  # noqa: E731
    face_keys, surface_keys = key(faces.astype(np.int64)), key(surface)
    on_surface = np.isin(face_keys, surface_keys)
    counts = {}
    for k, s in zip(face_keys[on_surface].tolist(), side[on_surface].tolist()):
        counts.setdefault(k, []).append(s)
    assert len(counts) == len(surface_keys)
    assert all(sorted(v) == [False, True] for v in counts.values())
    # Flat tetrahedra (TetGen keeps some when it does not optimise) have their centroid on the
    # surface, where the winding number is undefined: sample the others.
    p = tets["points"][t]
    volume = np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])))
    solid = np.flatnonzero(volume > 1e-9 * volume.max())
    rng = np.random.default_rng(0)
    pick = rng.choice(solid, size=min(samples, len(solid)), replace=False)
    centroids = tets["points"][t[pick]].mean(axis=1)
    winding = hc.winding_numbers(vertices, triangles, centroids)
    assert np.all(np.abs(np.abs(winding) - inside[pick]) < 1e-6)


@pytest.mark.parametrize("name,genus", GENUS_POSITIVE)
@pytest.mark.heavy
def test_genus_positive_meshes(data_dir, name, genus):
    vertices, triangles = read_off(data_dir / "genus_positive" / name)
    result = topstoc.handle_tunnel_loops(vertices, triangles)
    assert [c.genus for c in result.components] == [genus]
    assert result.components[0].route == "full"
    check_component(vertices, triangles, result.components[0])


def test_every_shared_genus_positive_mesh_has_g_loops_of_each_kind(shared_meshes, data_dir):
    """The shared collection may hold more meshes than tests/data (whose copies are checked in
    full above): count and check the loops of the others."""
    for path in sorted((shared_meshes / "genus_positive").glob("*.off")):
        copy = data_dir / "genus_positive" / path.name
        if copy.exists() and copy.read_bytes() == path.read_bytes():
            continue
        vertices, triangles = read_off(path)
        result = topstoc.handle_tunnel_loops(vertices, triangles)
        for component in result.components:
            assert component.status == "ok", path.name
            assert len(component.handles) == len(component.tunnels) == component.genus > 0, path.name
            for loop in component.loops:
                assert hc.is_simple_edge_cycle(loop.vertices, triangles), path.name


@pytest.mark.parametrize("genus", [1, 2, 4])
def test_synthetic_slabs(genus):
    vertices, triangles = meshgen.genus_slab(genus)
    result = topstoc.handle_tunnel_loops(vertices, triangles)
    (component,) = result.components
    assert component.genus == genus
    check_component(vertices, triangles, component)
    # A unit slab with square holes: every tunnel goes around one hole (4 edges of length 2),
    # every handle around one bar (a 2 x 2 square section).
    assert sorted(round(loop.length, 6) for loop in component.tunnels) == [8.0] * genus
    assert sorted(round(loop.length, 6) for loop in component.handles) == [8.0] * genus


@pytest.mark.parametrize("nu,nv,major,minor", [(48, 24, 1.0, 0.3), (24, 12, 1.0, 0.35), (12, 6, 1.0, 0.35),
                                                 (40, 8, 1.0, 0.4), (16, 16, 1.0, 0.6)])
def test_torus_loops_are_meridian_and_inner_equator(nu, nv, major, minor):
    vertices, triangles = meshgen.torus(nu, nv, major, minor)
    (component,) = topstoc.handle_tunnel_loops(vertices, triangles).components
    check_component(vertices, triangles, component)
    (handle,), (tunnel,) = component.handles, component.tunnels
    # The meridian is a regular nv-gon of radius `minor`; the inner equator a regular nu-gon of
    # radius major - minor: the shortest loops of their classes on this grid.
    assert handle.length == pytest.approx(2 * nv * minor * np.sin(np.pi / nv))
    assert tunnel.length == pytest.approx(2 * nu * (major - minor) * np.sin(np.pi / nu))
    ring = np.round(np.hypot(vertices[tunnel.vertices, 0], vertices[tunnel.vertices, 1]), 9)
    assert np.all(ring == round(major - minor, 9))


def test_several_components_each_get_their_loops():
    parts = [meshgen.torus(24, 12), meshgen.icosphere(1), meshgen.genus_slab(2), meshgen.grid(3, 3)]
    vertices, triangles = meshgen.disjoint(*parts)
    result = topstoc.handle_tunnel_loops(vertices, triangles)
    by_first = {c.first_vertex: c for c in result.components}
    offsets = np.cumsum([0] + [len(v) for v, _ in parts])[:-1]
    torus, sphere, slab, sheet = (by_first[o] for o in offsets)
    assert [torus.genus, sphere.genus, slab.genus, sheet.genus] == [1, 0, 2, 0]
    assert sphere.status == "ok" and not sphere.loops
    assert sheet.status == "open" and not sheet.loops and "boundary" in sheet.detail
    assert [c.first_vertex for c in result.components] == sorted(offsets)
    for component in (torus, slab):
        check_component(vertices, triangles, component)


def test_a_torus_inside_a_sphere_is_analysed_on_its_own():
    outer_v, outer_t = meshgen.icosphere(2)
    inner_v, inner_t = meshgen.torus(24, 12, 0.5, 0.15)
    vertices = np.concatenate([outer_v * 3.0, inner_v])
    triangles = np.concatenate([outer_t, inner_t + len(outer_v)]).astype(np.int32)
    result = topstoc.handle_tunnel_loops(vertices, triangles)
    torus = [c for c in result.components if c.genus == 1][0]
    check_component(inner_v, inner_t, topstoc.handle_tunnel_loops(inner_v, inner_t).components[0])
    assert len(torus.handles) == len(torus.tunnels) == 1
    (handle,) = torus.handles
    assert handle.length == pytest.approx(2 * 12 * 0.15 * np.sin(np.pi / 12))


@pytest.mark.parametrize("name,target", [("cgal_elephant.off", 600), ("cgal_knot1.off", 400),
                                         ("cgal_turbine.off", 2000), ("cgal_couplingdown.off", 700)])
@pytest.mark.heavy
def test_coarse_route_gives_valid_loops_on_the_full_mesh(data_dir, name, target):
    vertices, triangles = read_off(data_dir / "genus_positive" / name)
    result = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=target)
    (component,) = result.components
    assert component.route == "coarse"
    assert component.analysed_vertices < len(vertices)
    check_component(vertices, triangles, component)


@pytest.mark.heavy
def test_coarse_route_on_a_subdivided_mesh_matches_the_full_route(data_dir):
    vertices, triangles = meshgen.subdivide(*read_off(data_dir / "genus_positive" / "cgal_eight.off"), 2)
    coarse = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=300).components[0]
    full = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=0).components[0]
    assert (coarse.route, full.route) == ("coarse", "full")
    check_component(vertices, triangles, coarse)
    # Tightened on the full mesh, the coarse route's loops are about as short as the full route's.
    for a, b in ((coarse.handles, full.handles), (coarse.tunnels, full.tunnels)):
        assert sum(x.length for x in a) <= 1.1 * sum(x.length for x in b)


def test_shortening_keeps_the_class_and_never_lengthens(data_dir):
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_elephant.off")
    (component,) = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=500).components
    apex = len(vertices)
    surface = [triangles]
    b1 = hc.betti(surface)[1]
    shortened = 0
    for loop in component.loops:
        assert hc.is_simple_edge_cycle(loop.initial_vertices, triangles)
        assert hc.loop_length(vertices, loop.vertices) <= hc.loop_length(vertices, loop.initial_vertices) + 1e-12
        # Same non-zero class over Z2: coning off both kills one dimension only.
        assert hc.coned_b1(surface, [loop.initial_vertices], apex) == b1 - 1
        assert hc.coned_b1(surface, [loop.initial_vertices, loop.vertices], apex) == b1 - 1
        shortened += loop.length < loop.initial_length - 1e-9
    assert shortened >= 1  # the coarse route's mapped loops zigzag through clusters


def test_without_shortening_loops_are_returned_as_selected(data_dir):
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_eight.off")
    (component,) = topstoc.handle_tunnel_loops(vertices, triangles, shorten=False).components
    for loop in component.loops:
        np.testing.assert_array_equal(loop.vertices, loop.initial_vertices)
    check_component(vertices, triangles, component)


def test_edge_count_metric(data_dir):
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_double-torus-example.off")
    by_edges = topstoc.handle_tunnel_loops(vertices, triangles, metric="edges").components[0]
    by_length = topstoc.handle_tunnel_loops(vertices, triangles).components[0]
    check_component(vertices, triangles, by_edges)
    assert sum(len(x) for x in by_edges.loops) <= sum(len(x) for x in by_length.loops)


@pytest.mark.heavy
def test_field_three_agrees(data_dir):
    """Over Z3 too: the loops are genuine handles and tunnels, not only modulo 2."""
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_anchor_dense.off")
    (component,) = topstoc.handle_tunnel_loops(vertices, triangles).components
    check_component(vertices, triangles, component, field=3)


def test_deterministic_and_input_untouched(data_dir):
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_couplingdown.off")
    v0, t0 = vertices.copy(), triangles.copy()
    first = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=800)
    second = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=800)
    np.testing.assert_array_equal(vertices, v0)
    np.testing.assert_array_equal(triangles, t0)
    for a, b in zip(first.handles + first.tunnels, second.handles + second.tunnels):
        np.testing.assert_array_equal(a.vertices, b.vertices)
        assert a.generator == b.generator


def test_genus_zero_and_empty():
    vertices, triangles = meshgen.icosphere(2)
    (component,) = topstoc.handle_tunnel_loops(vertices, triangles).components
    assert (component.genus, component.status, component.loops) == (0, "ok", ())
    with pytest.raises(ValueError, match="no vertices"):
        topstoc.handle_tunnel_loops(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32))


def test_open_surface_is_reported_not_refused(data_dir):
    vertices, triangles = read_off(data_dir / "open_boundary" / "cgal_elephant-with-holes.off")
    result = topstoc.handle_tunnel_loops(vertices, triangles)
    assert result.components and all(c.status == "open" and not c.loops for c in result.components)


def test_non_manifold_mesh_is_refused_with_the_reason(data_dir):
    vertices, triangles = meshgen.disjoint(meshgen.torus(12, 6), meshgen.icosphere(1))
    # Glue a fin onto an edge of the torus: that edge gets three triangles.
    a, b = triangles[0, 0], triangles[0, 1]
    fin = len(vertices)
    vertices = np.concatenate([vertices, [[5.0, 5.0, 5.0]]])
    triangles = np.concatenate([triangles, [[a, b, fin]]]).astype(np.int32)
    with pytest.raises(ValueError, match=r"non-manifold.*edge.*three or more triangles"):
        topstoc.handle_tunnel_loops(vertices, triangles)


def test_non_orientable_surface_is_refused():
    vertices, triangles = meshgen.klein_bottle()
    with pytest.raises(ValueError, match="non-orientable"):
        topstoc.handle_tunnel_loops(vertices, triangles)


def test_self_intersecting_surface_is_refused_with_the_triangles():
    # A spindle torus (minor radius above the major one) passes through itself.
    vertices, triangles = meshgen.torus(24, 12, major=0.3, minor=0.5)
    assert len(topstoc.self_intersections(vertices, triangles)) > 0
    with pytest.raises(ValueError, match=r"intersects itself.*triangles \(\d+, \d+, \d+\) and"):
        topstoc.handle_tunnel_loops(vertices, triangles)
    with pytest.raises(ValueError, match="intersects itself"):
        topstoc.tetrahedralize_surface(vertices, triangles)


def unit_cube(z0=0.0, shift=0.0):
    v = np.array([[x + shift, y + shift, z + z0] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    f = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6], [0, 2, 6],
         [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return v, np.array(f, dtype=np.int32)


def test_tetgen_sees_perturbed_positions_and_falls_back_to_exact():
    """TetGen runs on vertices moved by at most 1e-7 of their shortest edge (its exact arithmetic
    on the tube's co-circular rings is slow); the points returned are the surface's own, and
    the sides are right. Where that move would make faces cross (two cubes 1e-9 apart), TetGen
    refuses it and the exact positions are used."""
    vertices, triangles = loop_families.torus_knot(2, 3, samples=120, around=8)
    tets = topstoc.tetrahedralize_surface(vertices, triangles)
    assert tets["perturbed"]
    assert np.array_equal(tets["points"][:len(vertices)], vertices)
    inside = tets["inside"].astype(bool)
    assert hc.betti([tets["tets"][inside]])[:3] == [1, 1, 0]
    assert hc.betti([tets["tets"][~inside]])[:3] == [1, 1, 1]
    check_sides(vertices, triangles, tets)
    for gap, perturbed in ((1e-5, True), (1e-9, False)):
        (v1, f1), (v2, f2) = unit_cube(), unit_cube(1 + gap, shift=0.3)
        vertices, triangles = np.vstack([v1, v2]), np.vstack([f1, f2 + 8])
        tets = topstoc.tetrahedralize_surface(vertices, triangles)
        assert tets["perturbed"] == perturbed, gap
        assert np.array_equal(tets["points"][:16], vertices)
        inside = tets["inside"].astype(bool)
        assert hc.betti([tets["tets"][inside]])[:3] == [2, 0, 0]
        assert hc.betti([tets["tets"][~inside]])[:3] == [1, 0, 2]


@pytest.mark.heavy
def test_self_intersections_agree_with_brute_force():
    vertices, triangles = meshgen.torus(10, 5, major=0.3, minor=0.5)
    # Generic positions: the floating-point reference below is unreliable on exact coincidences.
    vertices = vertices + np.random.default_rng(1).normal(scale=1e-4, size=vertices.shape)
    pairs = {tuple(p) for p in topstoc.self_intersections(vertices, triangles).tolist()}
    assert pairs and all(a < b for a, b in pairs)
    # Brute force with a different test: a shared-nothing pair intersects when an edge of one
    # crosses the other (Moeller's segment-triangle test in floating point, generic here).
    for a in range(len(triangles)):
        for b in range(a + 1, len(triangles)):
            if set(triangles[a]) & set(triangles[b]):
                continue
            assert crosses(vertices, triangles[a], triangles[b]) == ((a, b) in pairs)
    clean_v, clean_t = meshgen.torus(16, 8)
    assert len(topstoc.self_intersections(clean_v, clean_t)) == 0


def crosses(vertices, t1, t2):
    def segment_hits(p, q, tri):
        a, b, c = vertices[tri]
        e1, e2, d = b - a, c - a, q - p
        h = np.cross(d, e2)
        det = e1 @ h
        if abs(det) < 1e-15:
            return False
        s = p - a
        u = (s @ h) / det
        qv = np.cross(s, e1)
        v = (d @ qv) / det
        t = (e2 @ qv) / det
        return 0 <= u <= 1 and 0 <= v and u + v <= 1 and 0 <= t <= 1
    return any(segment_hits(vertices[t1[i]], vertices[t1[(i + 1) % 3]], t2) for i in range(3)) or \
        any(segment_hits(vertices[t2[i]], vertices[t2[(i + 1) % 3]], t1) for i in range(3))


def test_progress_and_cancellation(data_dir):
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_elephant.off")
    calls = []
    topstoc.handle_tunnel_loops(vertices, triangles, progress=lambda f, stage: calls.append((f, stage)))
    fractions = [f for f, _ in calls]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    assert {"tetrahedralize", "persistence", "select loops", "shorten"} <= {s for _, s in calls}
    with pytest.raises(topstoc.Cancelled, match="cancelled during"):
        topstoc.handle_tunnel_loops(vertices, triangles, progress=lambda f, stage: stage != "persistence")

    def boom(fraction, stage):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        topstoc.handle_tunnel_loops(vertices, triangles, progress=boom)


def test_cancelling_tetgen_stops_it(data_dir):
    """Cancelling while TetGen runs (in its own process) stops it; the next run works."""
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_turbine.off")
    calls = []

    def stop_inside_tetgen(fraction, stage):
        calls.append(stage)
        return calls.count("tetrahedralize") < 3  # the first call opens the stage; later ones poll

    with pytest.raises(topstoc.Cancelled, match="tetrahedralize"):
        topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=0, progress=stop_inside_tetgen)
    assert calls.count("tetrahedralize") == 3
    assert topstoc.handle_tunnel_loops(vertices, triangles).components[0].genus == 11


def test_bad_arguments():
    vertices, triangles = meshgen.torus(12, 6)
    with pytest.raises(ValueError, match="metric"):
        topstoc.handle_tunnel_loops(vertices, triangles, metric="hops")
    with pytest.raises(ValueError, match="coarse_vertices"):
        topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=-5)
    with pytest.raises(ValueError, match="vertices and triangles"):
        topstoc.handle_tunnel_loops(vertices)
    with pytest.raises(ValueError, match="refers to vertex 1000"):
        topstoc.handle_tunnel_loops(vertices, triangles + 1000)
    with pytest.raises(ValueError, match="NaN|finite"):
        bad = vertices.copy()
        bad[3, 1] = np.nan
        topstoc.handle_tunnel_loops(bad, triangles)


def test_json_document(data_dir):
    vertices, triangles = read_off(data_dir / "genus_positive" / "cgal_eight.off")
    doc = topstoc.handle_tunnel_loops(vertices, triangles).as_json()
    (component,) = doc["components"]
    assert component["genus"] == 2
    assert len(component["handles"]) == len(component["tunnels"]) == 2
    assert all(isinstance(v, int) for loop in component["handles"] for v in loop)
