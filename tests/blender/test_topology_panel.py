"""Topology panel data and operators inside Blender: invariants against an independent
implementation (tests/reference.py), loops found and stepped through, select / cut / remove /
fill / delete with the invariants updated and attributes kept, undo restoring the mesh and its
analysis, bad input reported without a trace, and the overlays' arrays."""

import contextlib
import importlib

import bpy
import numpy as np
import pytest

import meshgen
import reference
from conftest import DATA
from helpers import make_object, positions, select_only


@pytest.fixture
def mods(ts):
    names = {"analysis": "blender.analysis.topology", "overlay_data": "blender.ui.overlay_data",
             "panel": "blender.ui.topology", "colors": "core.support.colors", "watch": "blender.preview.watch",
             "mesh_edit": "blender.io.mesh_edit"}
    return type("Mods", (), {key: importlib.import_module(f"{ts.__name__}.{name}") for key, name in names.items()})


def load(name, path):
    vertices, faces = reference.read_off(DATA / path)
    return make_object(name, vertices, faces)


def triangles_of(mesh):
    mesh.calc_loop_triangles()
    return np.array([t.vertices[:] for t in mesh.loop_triangles], dtype=np.int64).reshape(-1, 3)


def expected(mesh):
    """(V, E, F, duplicate triangles, per-component (chi, boundary loops, manifold, orientable)),
    computed independently on the complex (a repeated triangle is one simplex)."""
    triangles = triangles_of(mesh)
    unique = np.unique(np.sort(triangles, axis=1), axis=0)
    return (len(mesh.vertices), len(mesh.edges), len(mesh.polygons), len(triangles) - len(unique),
            reference.invariants(len(mesh.vertices), unique))


def panel_invariants(topology):
    return sorted((c.euler, c.boundary_loops if c.manifold else None, c.manifold,
                   c.orientable if c.manifold else None) for c in topology.components)


def reference_invariants(components):
    """Boundary loops compared on manifold components only: where boundary edges meet at a
    non-manifold edge the engine reports open chains, the reference one edge component."""
    return sorted(((chi, loops if manifold else None, manifold, orientable)
                   for chi, loops, manifold, orientable in components), key=order)


def order(row):
    return row[0], row[2], -1 if row[1] is None else row[1]


def assert_matches_reference(obj):
    topology = obj.topstoc.topology
    v, e, f, duplicates, components = expected(obj.data)
    assert (topology.vertices, topology.edges, topology.faces) == (v, e, f)
    assert topology.duplicate_triangles == duplicates
    assert sorted(panel_invariants(topology), key=order) == reference_invariants(components)
    assert topology.euler == v - e + f - duplicates
    assert topology.betti0 == len(components)
    if all(c[2] and c[3] for c in components):
        assert topology.genus == sum(reference.euler_genus(c[0], c[1]) for c in components)
    assert topology.boundary_loops == sum(c[1] for c in components if c[2])


def is_edge_cycle(mesh, ids):
    t = triangles_of(mesh)
    edges = {tuple(sorted(p)) for tri in t for p in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0]))}
    return len(set(ids)) == len(ids) >= 3 and all(tuple(sorted((a, b))) in edges
                                                  for a, b in zip(ids, np.roll(ids, -1)))


@pytest.mark.parametrize("path", ["genus_positive/cgal_eight.off", "genus_positive/cgal_elephant.off",
                                  "open_boundary/cgal_mushroom.off", "open_boundary/kivy_suzanne_monkey.obj"])
def test_analyse_matches_an_independent_count(mods, scene, path):
    if path.endswith(".obj"):
        bpy.ops.wm.obj_import(filepath=str(DATA / path))
        obj = bpy.context.selected_objects[0]
        select_only(obj)  # Suzanne has quads: V, E, F are Blender's counts
    else:
        obj = load("Mesh", path)
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    assert obj.topstoc.topology.state == "OK"
    assert_matches_reference(obj)
    assert mods.analysis.is_current(obj)


def test_quad_torus_and_loose_edges(mods, scene):
    bpy.ops.mesh.primitive_torus_add(major_segments=24, minor_segments=12)
    obj = bpy.context.active_object
    mesh = obj.data
    mesh.vertices.add(2)
    mesh.edges.add(1)
    mesh.edges[-1].vertices = (len(mesh.vertices) - 2, len(mesh.vertices) - 1)
    mesh.update()
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    t = obj.topstoc.topology
    assert (t.vertices, t.edges, t.faces) == (24 * 12 + 2, 2 * 24 * 12 + 1, 24 * 12)
    assert (t.betti0, t.betti1, t.betti2, t.euler) == (2, 2, 1, 1)  # torus + a wire edge
    surface = [c for c in t.components if c.faces]
    assert len(surface) == 1 and surface[0].genus == 1 and surface[0].faces == 24 * 12
    assert len(t["generator_edges"]) == 2 * 2


def test_find_loops_step_and_select(mods, scene):
    obj = load("Eight", "genus_positive/cgal_eight.off")
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    kinds = [loop.kind for loop in t.loops]
    assert kinds.count("HANDLE") == 2 and kinds.count("TUNNEL") == 2 and t.loops_state == "OK"
    for loop in t.loops:
        ids = mods.analysis.loop_vertices(loop)
        assert is_edge_cycle(obj.data, ids) and loop.num_edges == len(ids)
        co = positions(obj.data).astype(float)
        assert loop.length == pytest.approx(np.linalg.norm(co[ids] - co[np.roll(ids, -1)], axis=1).sum(), rel=1e-5)
    t.loop_index = 0
    assert bpy.ops.topstoc.loop_step(direction="PREVIOUS") == {"FINISHED"} and t.loop_index == 3
    assert bpy.ops.topstoc.loop_step(direction="NEXT") == {"FINISHED"} and t.loop_index == 0
    bpy.ops.topstoc.loop_step(direction="NEXT")
    ids = mods.analysis.loop_vertices(t.loops[1])
    assert bpy.ops.topstoc.select_loop() == {"FINISHED"} and obj.mode == "EDIT"
    bpy.ops.object.mode_set(mode="OBJECT")
    selected = {tuple(sorted(e.vertices)) for e in obj.data.edges if e.select}
    assert selected == {tuple(sorted((int(a), int(b)))) for a, b in zip(ids, np.roll(ids, -1))}
    assert not any(p.select for p in obj.data.polygons)


def test_loop_list_is_sorted_by_size_relative_to_the_diagonal(mods, scene):
    """Handles, tunnels and holes in one list, shortest first, each with its length over the
    bounding box's diagonal; checked against lengths computed here from the input's positions,
    and still sorted after an edit carries the loops over."""
    import cleanup_meshes

    block, block_triangles = cleanup_meshes.block_with_arches(3, 2, jitter=0.05, seed=4)
    plate, plate_triangles = cleanup_meshes.perforated_plate(1, 0, side=6, jitter=0.05, seed=4)
    vertices = np.vstack([block, plate + [0.0, 0.0, -3.0]])  # a plate (edge 24, hole 4) below the block
    triangles = np.vstack([block_triangles, plate_triangles + len(block)])
    obj = make_object("Arches", vertices, triangles)
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    diagonal = np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0))

    def independent(item):
        ids = mods.analysis.loop_vertices(item)
        return np.linalg.norm(vertices[ids] - vertices[np.roll(ids, -1)], axis=1).sum()

    lengths = [independent(item) for item in t.loops]
    assert sorted(item.kind for item in t.loops) == ["BOUNDARY"] * 2 + ["HANDLE"] * 5 + ["TUNNEL"] * 5
    assert lengths == sorted(lengths) and lengths[0] < 6 < lengths[-1]  # small flaws first, large last
    assert t.loops[0].kind != "BOUNDARY" or lengths[0] < 5 and t.loops[-1].kind == "BOUNDARY"  # the plate's edge last
    for item, length in zip(t.loops, lengths):
        assert item.length == pytest.approx(length, rel=1e-5)
        assert item.relative == pytest.approx(length / diagonal, rel=1e-5)
        assert mods.panel.loop_size(item).startswith(f"{100 * length / diagonal:.2g} %")
    handles = [item.name for item in t.loops if item.kind == "HANDLE"]
    assert handles == [f"Handle {i}" for i in range(1, 6)]  # numbered in the list's order
    t.loop_index = [item.kind for item in t.loops].index("HANDLE")
    assert bpy.ops.topstoc.remove_loop() == {"FINISHED"}
    assert [item.length for item in t.loops] == sorted(item.length for item in t.loops)
    assert sum(item.kind == "HANDLE" for item in t.loops) >= 3


def add_attributes(obj):
    mesh = obj.data
    uv = mesh.uv_layers.new(name="UVMap")
    values = np.random.default_rng(0).random(2 * len(mesh.loops)).astype(np.float32)
    uv.data.foreach_set("uv", values)
    ids = mesh.attributes.new("vertex_id", "INT", "POINT")
    ids.data.foreach_set("value", np.arange(len(mesh.vertices), dtype=np.int32))
    group = obj.vertex_groups.new(name="Group")
    group.add(list(range(0, len(mesh.vertices), 3)), 0.5, "REPLACE")
    mesh.edges[0].use_seam = True
    return values.reshape(-1, 2)


def test_remove_and_cut_update_invariants_and_keep_attributes(mods, scene):
    obj = load("Eight", "genus_positive/cgal_eight.off")
    uvs = add_attributes(obj)
    loop_vertex = np.array([loop.vertex_index for loop in obj.data.loops])
    seam = tuple(sorted(obj.data.edges[0].vertices))
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    t.loop_index = [loop.kind for loop in t.loops].index("HANDLE")
    handle = mods.analysis.loop_vertices(t.loops[t.loop_index])
    assert bpy.ops.topstoc.remove_loop() == {"FINISHED"}
    assert_matches_reference(obj)
    assert t.genus == 1 and t.boundary_loops == 0 and t.betti1 == 2
    mesh = obj.data
    # every vertex keeps its attribute: copies carry their source id, patch vertices none here
    ids = np.empty(len(mesh.vertices), dtype=np.int32)
    mesh.attributes["vertex_id"].data.foreach_get("value", ids)
    co_new = positions(mesh)
    untouched = ~np.isin(ids, handle)
    reference_co = np.array(reference.read_off(DATA / "genus_positive/cgal_eight.off")[0], dtype=np.float32)
    np.testing.assert_allclose(co_new[untouched], reference_co[ids[untouched]], atol=1e-6)
    # corners away from the loop keep their UVs exactly
    new_uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    mesh.uv_layers["UVMap"].data.foreach_get("uv", new_uv)
    new_uv = new_uv.reshape(-1, 2)
    old_corner = {(int(loop_vertex[i]), tuple(uvs[i])) for i in range(len(loop_vertex))}
    kept = [(int(ids[mesh.loops[i].vertex_index]), tuple(new_uv[i])) for i in range(len(mesh.loops))]
    assert sum(k in old_corner for k in kept) >= 0.9 * len(kept)
    assert all(len(v.groups) == (1 if ids[v.index] % 3 == 0 else 0) for v in mesh.vertices)
    assert any(e.use_seam and tuple(sorted(ids[list(e.vertices)])) == seam for e in mesh.edges)
    # the other handle and tunnel loops were carried over as edge cycles of the new mesh
    kinds = [loop.kind for loop in t.loops]
    assert kinds.count("HANDLE") == 1
    for loop in t.loops:
        assert is_edge_cycle(mesh, mods.analysis.loop_vertices(loop))
    t.loop_index = kinds.index("HANDLE")
    assert bpy.ops.topstoc.cut_loop() == {"FINISHED"}
    assert_matches_reference(obj)
    assert t.genus == 0 and t.boundary_loops == 2
    boundaries = [loop for loop in t.loops if loop.kind == "BOUNDARY"]
    assert len(boundaries) == 2 and all(loop.fillable for loop in boundaries)
    t.loop_index = list(t.loops).index(boundaries[0])
    assert bpy.ops.topstoc.fill_holes(mode="ACTIVE") == {"FINISHED"}
    assert t.boundary_loops == 1
    assert_matches_reference(obj)


def test_fill_selected_all_and_delete_faces(mods, scene):
    obj = load("Elephant", "open_boundary/cgal_elephant-with-holes.off")
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    t = obj.topstoc.topology
    holes = t.boundary_loops
    assert holes >= 2
    mesh = obj.data
    before = len(mesh.polygons)
    mesh.vertices.foreach_set("select", np.ones(len(mesh.vertices), dtype=bool))
    with pytest.raises(RuntimeError, match="Edit Mode"):  # Object Mode: the selection is not shown
        bpy.ops.topstoc.fill_holes(mode="SELECTED")
    assert t.boundary_loops == holes
    for items in (mesh.vertices, mesh.edges, mesh.polygons):  # Edit Mode flushes edges' to vertices
        items.foreach_set("select", np.zeros(len(items), dtype=bool))
    with in_edit_mode(), pytest.raises(RuntimeError, match="no hole has a selected boundary edge"):
        bpy.ops.topstoc.fill_holes(mode="SELECTED")
    assert len(obj.data.polygons) == before and t.boundary_loops == holes       # nothing lost
    assert t.edit_state == "ERROR" and "no hole has a selected boundary edge" in t.edit_message  # in the panel
    first = mods.analysis.loop_vertices([loop for loop in t.loops if loop.kind == "BOUNDARY"][0])
    mesh = obj.data
    mesh.vertices.foreach_set("select", np.isin(np.arange(len(mesh.vertices)), first[:2]))
    with in_edit_mode():
        assert bpy.ops.topstoc.fill_holes(mode="SELECTED") == {"FINISHED"}
    assert t.boundary_loops == holes - 1
    assert_matches_reference(obj)
    assert bpy.ops.topstoc.fill_holes(mode="ALL") == {"FINISHED"}
    assert t.boundary_loops == 0 and all(c.closed for c in t.components)
    assert_matches_reference(obj)
    mesh = obj.data
    for items in (mesh.vertices, mesh.edges, mesh.polygons):
        items.foreach_set("select", np.zeros(len(items), dtype=bool))
    with in_edit_mode(), pytest.raises(RuntimeError, match="no faces are selected"):
        bpy.ops.topstoc.delete_faces()
    count = len(obj.data.polygons)
    bpy.context.tool_settings.mesh_select_mode = (False, False, True)
    obj.data.polygons[10].select = True
    with in_edit_mode():
        assert bpy.ops.topstoc.delete_faces() == {"FINISHED"}
    assert len(obj.data.polygons) == count - 1 and t.boundary_loops == 1
    assert_matches_reference(obj)
    assert t.genus == 3


@contextlib.contextmanager
def in_edit_mode():
    """Edit Mode around a block (the selection set in Object Mode carries in and out)."""
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        yield
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


def test_delete_faces_refuses_object_mode_and_an_empty_mesh_is_called_empty(mods, scene):
    """Object Mode hides the selection (after an import it may be every face): Delete Selected
    Faces acts only on what Edit Mode shows; a mesh with no faces is not "ready to print"."""
    obj = load("Eight", "genus_positive/cgal_eight.off")
    obj.data.polygons.foreach_set("select", np.ones(len(obj.data.polygons), dtype=bool))
    count = len(obj.data.polygons)
    with pytest.raises(RuntimeError, match="Edit Mode"):
        bpy.ops.topstoc.delete_faces()
    assert len(obj.data.polygons) == count
    with in_edit_mode():
        assert bpy.ops.topstoc.delete_faces() == {"FINISHED"}
    assert len(obj.data.polygons) == 0
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    summary = mods.panel.plain_summary(obj.topstoc.topology)
    assert "empty" in summary and "ready to print" not in summary


def test_edit_mode_operators_and_quads(mods, scene):
    bpy.ops.mesh.primitive_torus_add(major_segments=16, minor_segments=8)
    obj = bpy.context.active_object
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="OBJECT")
    obj.data.polygons[0].select = True
    bpy.ops.object.mode_set(mode="EDIT")
    assert bpy.ops.topstoc.delete_faces() == {"FINISHED"}
    assert obj.mode == "EDIT"                                     # back where the user was
    bpy.ops.object.mode_set(mode="OBJECT")
    t = obj.topstoc.topology
    assert len(obj.data.polygons) == 16 * 8 - 1 and t.boundary_loops == 1
    assert all(len(p.vertices) == 4 for p in obj.data.polygons)   # quads stay quads
    assert bpy.ops.topstoc.fill_holes(mode="ALL") == {"FINISHED"}
    assert t.boundary_loops == 0 and t.genus == 1
    assert sum(len(p.vertices) == 4 for p in obj.data.polygons) == 16 * 8 - 1


def state(obj):
    t = obj.topstoc.topology
    if obj.mode == "EDIT":  # Edit Mode selection lives in the edit mesh (left as the user would)
        import bmesh

        selected = sum(e.select for e in bmesh.from_edit_mesh(obj.data).edges)
    else:
        selected = sum(e.select for e in obj.data.edges)
    return (len(obj.data.vertices), len(obj.data.polygons), t.genus, t.boundary_loops, len(t.loops), selected)


def prepare_for(operator, obj, mods):
    """Makes the active loop / the selection what ``operator`` needs; returns its kwargs."""
    t = obj.topstoc.topology
    mesh = obj.data
    mesh.vertices.foreach_set("select", np.zeros(len(mesh.vertices), dtype=bool))
    mesh.edges.foreach_set("select", np.zeros(len(mesh.edges), dtype=bool))
    mesh.polygons.foreach_set("select", np.zeros(len(mesh.polygons), dtype=bool))
    if operator in ("select_loop", "cut_loop", "remove_loop"):
        t.loop_index = [loop.kind for loop in t.loops].index("HANDLE")
        return {}
    # fill_holes: cut first (so there are holes), then make one of them the active loop (filling
    # the selected holes needs Edit Mode, which this Object Mode undo test does not enter)
    t.loop_index = [loop.kind for loop in t.loops].index("HANDLE")
    assert bpy.ops.topstoc.cut_loop() == {"FINISHED"}
    t.loop_index = [loop.kind for loop in t.loops].index("BOUNDARY")
    return {"mode": "ACTIVE"}


@pytest.mark.parametrize("operator", ["select_loop", "cut_loop", "remove_loop", "fill_holes"])  # delete: Edit Mode
def test_every_operator_updates_the_invariants_and_undo_restores(mods, scene, operator):
    obj = load("Eight", "genus_positive/cgal_eight.off")
    name = obj.name
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    kwargs = prepare_for(operator, obj, mods)
    bpy.ops.ed.undo_push(message="before")
    before = state(obj)
    assert getattr(bpy.ops.topstoc, operator)("EXEC_DEFAULT", True, **kwargs) == {"FINISHED"}  # True: push undo
    obj = bpy.data.objects[name]
    after = state(obj)
    assert after != before
    if operator != "select_loop":
        assert_matches_reference(obj)  # re-analysed automatically
        assert mods.analysis.is_current(obj, fresh=True)
    bpy.ops.ed.undo()
    obj = bpy.data.objects[name]                                  # undo replaces Python references
    assert obj.mode == "OBJECT" and state(obj) == before
    assert mods.analysis.is_current(obj, fresh=True)              # the analysis came back with the mesh
    assert_matches_reference(obj)


def test_self_intersecting_mesh_reports_the_tetgen_refusal(mods, scene):
    v, f = meshgen.torus(24, 12, major=0.3, minor=0.35)  # a spindle torus: the tube passes through itself
    obj = make_object("Spindle", v, f)
    assert bpy.ops.topstoc.analyse() == {"FINISHED"} and obj.topstoc.topology.genus == 1
    with pytest.raises(RuntimeError, match="intersects itself") as error:
        bpy.ops.topstoc.find_loops()
    t = obj.topstoc.topology
    assert t.loops_state == "ERROR" and "intersects itself" in t.loops_message
    assert "Spindle" in str(error.value) and "Traceback" not in t.loops_message
    assert len(obj.data.vertices) == len(v) and t.state == "OK"   # nothing lost, invariants kept


def test_nonmanifold_mesh_loop_search_reports_in_the_panel(mods, ts, scene):
    data = importlib.import_module(ts.__name__ + ".core.api.io").read_mesh(
        str(DATA / "nonmanifold_degenerate/openscad_issue1580-back-to-back.stl"))
    obj = make_object("Scan", data.vertices, data.triangles)
    assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    t = obj.topstoc.topology
    assert t.nonmanifold_edges == 2 and t.nonmanifold_vertices == 3 and t.genus == -1
    assert t.duplicate_triangles == 1                   # the shared face, counted once (and shown)
    assert_matches_reference(obj)
    count = len(obj.data.polygons)
    with pytest.raises(RuntimeError, match="manifold"):
        bpy.ops.topstoc.find_loops()
    assert t.loops_state == "ERROR" and "manifold" in t.loops_message and "Traceback" not in t.loops_message
    assert len(obj.data.polygons) == count
    shown = mods.overlay_data.topology_primitives(obj, bpy.context.scene.topstoc.overlays)
    assert {p.name for p in shown} >= {"nonmanifold_edges"}


def test_find_loops_searches_past_a_refused_component(mods, scene):
    """A non-manifold piece beside a genus-2 block: Find Loops used to fail on the whole mesh;
    now it lists the block's loops and names the refused piece in one line of its message."""
    import cleanup_meshes

    block, block_triangles = cleanup_meshes.block_with_arches(2, 0, jitter=0.05, seed=5)
    fin, fin_triangles = meshgen.tetrahedra_sharing_edge()
    n = len(block)
    obj = make_object("Two", np.vstack([block, fin + [0.0, 0.0, 20.0]]),
                      np.vstack([block_triangles, fin_triangles + n]))
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    assert t.loops_state == "OK" and "\n" not in t.loops_message
    assert f"component 1 (from vertex {n}): non-manifold" in t.loops_message, t.loops_message
    kinds = [loop.kind for loop in t.loops]
    assert kinds.count("HANDLE") == kinds.count("TUNNEL") == 2
    assert all(mods.analysis.loop_vertices(loop).max() < n for loop in t.loops)


def test_loop_view_looks_through_the_loop(ts):
    """Frame Loop's view: centred on the loop, four radii away, along its plane's normal from the
    viewer's side; a straight run of points keeps the view's direction."""
    frame = importlib.import_module(f"{ts.__name__}.blender.operators.frame_loop")
    rng = np.random.default_rng(3)
    normal = np.array([1.0, 2.0, 2.0]) / 3.0
    u = np.cross(normal, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 5))
    centre = np.array([4.0, -1.0, 0.5])
    points = centre + 0.02 * (np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * v)
    for viewer in (normal, -normal + [0.1, 0, 0]):
        got_centre, distance, directions = frame.loop_view(points, viewer)
        np.testing.assert_allclose(got_centre, points.mean(axis=0), atol=1e-12)
        radius = np.linalg.norm(points - points.mean(axis=0), axis=1).max()
        assert distance == pytest.approx(frame.RADII * radius)
        first = directions[0]
        assert abs(abs(first @ normal) - 1) < 1e-9 and first @ viewer > 0 and len(directions) == 15
        assert all(abs(abs(d @ normal) - np.sqrt(0.5)) < 1e-9 for d in directions[2:10])  # 45 degrees to the plane
    line = np.outer(np.arange(4.0), [1.0, 0.0, 0.0])
    assert len(frame.loop_view(line, normal)[2]) == 1  # a straight run: the present direction only


def test_frame_loop_looks_from_outside(mods, scene, ts):
    """A handle loop goes round a tube: through it (its plane's normal) the view would stand inside
    the tube, so Frame Loop looks from a side the loop is seen from."""
    frame = importlib.import_module(f"{ts.__name__}.blender.operators.frame_loop")
    obj = make_object("Torus", *meshgen.torus(24, 12))
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    handle = next(loop for loop in t.loops if loop.kind == "HANDLE")
    points = positions(obj.data)[mods.analysis.loop_vertices(handle)].astype(np.float64)
    centre, distance, directions = frame.loop_view(points, np.array([0.0, 0.0, 1.0]))
    shares = [frame.visible_share(obj, centre + distance * d, points) for d in directions]
    assert abs(directions[0][2]) < 1e-6  # round the tube: its plane is upright, the tube's axis level
    print("visible shares of the handle loop per direction:", [round(x, 2) for x in shares])
    assert shares[0] == shares[1] == 0.0  # through the tube: inside the mesh
    assert max(shares) >= 0.4


def test_overlay_arrays_follow_the_analysis(mods, scene):
    obj = load("Eight", "genus_positive/cgal_eight.off")
    bpy.ops.topstoc.find_loops()
    t = obj.topstoc.topology
    show = bpy.context.scene.topstoc.overlays
    t.loop_index = [loop.kind for loop in t.loops].index("HANDLE")
    prims = {p.name: p for p in mods.overlay_data.topology_primitives(obj, show)}
    co = positions(obj.data)
    active = mods.analysis.loop_vertices(t.loops[t.loop_index])
    np.testing.assert_allclose(prims["active_loop"].positions.reshape(-1, 2, 3)[:, 0], co[active])
    assert prims["active_loop"].size == "active" and prims["active_loop"].color == mods.colors.HANDLE
    # its corners as dots of the active width too: a tiny loop shows as a dot at least when zoomed out
    np.testing.assert_allclose(prims["active_loop_points"].positions, co[active])
    assert prims["active_loop_points"].size == "active" and prims["active_loop_points"].kind == "POINTS"
    handle_edges = sum(loop.num_edges for i, loop in enumerate(t.loops) if loop.kind == "HANDLE" and i != t.loop_index)
    assert len(prims["handles"]) == 2 * handle_edges and prims["tunnels"].color == mods.colors.TUNNEL
    assert len(prims["generators"]) == 2 * 4 and prims["generators"].color == mods.colors.GENERATOR
    show.show_handles = False
    names = {p.name for p in mods.overlay_data.topology_primitives(obj, show)}
    assert "handles" not in names and "active_loop" not in names and "tunnels" in names
    # a changed mesh draws nothing rather than loops at wrong places
    bpy.ops.mesh.primitive_cube_add()
    obj.data = bpy.context.active_object.data
    assert mods.overlay_data.topology_primitives(obj, show) == []


def test_topology_panels_draw_in_every_state(mods, scene):
    from test_registration import fake_panel

    obj = load("Eight", "genus_positive/cgal_eight.off")
    seen = set()
    for step in ("none", "analysed", "loops", "error"):
        if step == "analysed":
            bpy.ops.topstoc.analyse()
        elif step == "loops":
            bpy.ops.topstoc.find_loops()
        elif step == "error":
            obj.topstoc.topology.state, obj.topstoc.topology.message = "ERROR", "a clear message " * 8
        for cls in mods.panel.CLASSES:
            if not hasattr(cls, "draw") or issubclass(cls, bpy.types.UIList):
                continue
            if hasattr(cls, "poll") and not cls.poll(bpy.context):
                continue
            fake = fake_panel(cls, seen)
            cls.draw(fake, bpy.context)
    assert {"topstoc.analyse", "topstoc.find_loops", "topstoc.loop_step", "topstoc.select_loop",
            "topstoc.cut_loop", "topstoc.remove_loop", "topstoc.fill_holes", "topstoc.delete_faces",
            "show_handles", "show_generators", "line_width"} <= seen
    rows = dict(mods.panel.invariant_rows(obj.topstoc.topology))
    assert rows["Genus"] == "2" and rows["β0 / β1 / β2"] == "1 / 4 / 1" and rows["χ"] == "-2"


def test_edit_mode_delete_undo_gives_the_faces_back(mods, scene):
    import bmesh

    obj = load("Eight", "genus_positive/cgal_eight.off")
    name = obj.name
    bpy.ops.topstoc.analyse()
    mesh = obj.data
    mesh.vertices.foreach_set("select", np.zeros(len(mesh.vertices), dtype=bool))
    mesh.edges.foreach_set("select", np.zeros(len(mesh.edges), dtype=bool))
    mesh.polygons.foreach_set("select", np.arange(len(mesh.polygons)) < 5)
    bpy.context.tool_settings.mesh_select_mode = (False, False, True)
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.ed.undo_push(message="selected")
    assert bpy.ops.topstoc.delete_faces("EXEC_DEFAULT", True) == {"FINISHED"}
    obj = bpy.data.objects[name]
    assert obj.mode == "EDIT" and len(bmesh.from_edit_mesh(obj.data).faces) == 634 - 5
    assert obj.topstoc.topology.boundary_loops >= 1
    bpy.ops.ed.undo()
    obj = bpy.data.objects[name]
    assert obj.mode == "EDIT" and len(bmesh.from_edit_mesh(obj.data).faces) == 634
    bpy.ops.object.mode_set(mode="OBJECT")
    # The panel never shows figures of another mesh: either the analysis came back with the
    # mesh, or it knows it no longer fits (and the overlays show nothing).
    if mods.analysis.is_current(obj, fresh=True):
        assert_matches_reference(obj)
    else:
        assert mods.overlay_data.topology_primitives(obj, bpy.context.scene.topstoc.overlays) == []
    assert bpy.ops.topstoc.analyse() == {"FINISHED"} and obj.topstoc.topology.genus == 2


def test_loops_through_quad_diagonals_cut_and_remove(mods, scene):
    bpy.ops.mesh.primitive_torus_add(major_segments=20, minor_segments=10)
    obj = bpy.context.active_object
    uv_before = {}
    mesh = obj.data
    uv = mesh.uv_layers.active.data
    for poly in mesh.polygons:
        uv_before[tuple(sorted(poly.vertices))] = sorted(tuple(uv[i].uv) for i in poly.loop_indices)
    assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    t = obj.topstoc.topology
    assert [loop.kind for loop in t.loops].count("HANDLE") == 1
    t.loop_index = [loop.kind for loop in t.loops].index("TUNNEL")
    assert bpy.ops.topstoc.remove_loop() == {"FINISHED"}
    assert t.genus == 0 and t.boundary_loops == 0
    assert_matches_reference(obj)
    mesh = obj.data
    sizes = [len(p.vertices) for p in mesh.polygons]
    assert sizes.count(4) >= 20 * 10 - 2 * 20  # quads away from the loop stay quads
    uv = mesh.uv_layers.active.data
    kept = 0
    for poly in mesh.polygons:                 # untouched quads keep their UVs exactly
        key = tuple(sorted(poly.vertices))
        if len(poly.vertices) == 4 and key in uv_before:
            assert sorted(tuple(uv[i].uv) for i in poly.loop_indices) == uv_before[key]
            kept += 1
    assert kept >= 20 * 10 - 2 * 20 - 2


def test_edit_on_a_from_pydata_mesh_keeps_edge_flags(mods, scene):
    """A mesh made by a script (from_pydata, left as Blender makes it: in 5.0.x with a mistyped
    ``.select_edge``) is edited in place without crashing; seams and sharp edges carry over, the
    mistyped selection is not read, and the result's edge flags are writable."""
    vertices, faces = meshgen.torus(16, 8)
    mesh = bpy.data.meshes.new("Scripted")
    mesh.from_pydata(vertices.tolist(), [], faces.tolist())
    obj = bpy.data.objects.new("Scripted", mesh)
    bpy.context.scene.collection.objects.link(obj)
    select_only(obj)
    pairs = np.sort(np.array([e.vertices[:] for e in mesh.edges]), axis=1)
    marked = np.arange(len(mesh.edges)) % 4 == 0
    mesh.edges.foreach_set("use_seam", marked)
    mesh.edges.foreach_set("use_edge_sharp", marked)
    marked_pairs = {tuple(p) for p in pairs[marked].tolist()}
    readable = "select" not in mods.mesh_edit.edge_flags.mistyped_edge_flags(mesh)
    mesh.polygons.foreach_set("select", np.zeros(len(mesh.polygons), dtype=bool))
    mesh.polygons[3].select = True
    with in_edit_mode():
        assert bpy.ops.topstoc.delete_faces() == {"FINISHED"}
    out = obj.data
    assert len(out.polygons) == len(faces) - 1
    assert mods.mesh_edit.edge_flags.mistyped_edge_flags(out) == {}
    out_pairs = [tuple(sorted(e.vertices[:])) for e in out.edges]
    # delete_faces keeps every vertex (same ids), so edges are compared by their vertex pairs
    assert {p for p, e in zip(out_pairs, out.edges) if e.use_seam} == marked_pairs
    assert {p for p, e in zip(out_pairs, out.edges) if e.use_edge_sharp} == marked_pairs
    flags = np.arange(len(out.edges)) % 3 == 0
    out.edges.foreach_set("select", flags)
    read = np.zeros(len(out.edges), dtype=bool)
    out.edges.foreach_get("select", read)
    np.testing.assert_array_equal(read, flags)
    print("edge selection readable on the input:", readable)


def test_an_edit_keeps_every_element_flag(mods, scene):
    """Fill Holes on a torus with a hole, whose vertices, edges and faces carry every flag the
    edit copies, set element by element: every element that was there keeps its flags, read back
    element by element (Blender 4.0+ keeps them as attributes, copied as such; 3.x in its
    structs). Crease is an attribute from 4.0 on, freestyle marks are gone in 5.0."""
    vertices, faces = meshgen.torus(16, 8)
    obj = make_object("Flags", vertices, [f for i, f in enumerate(faces) if i != 3])
    mesh = obj.data
    rng = np.random.default_rng(11)
    flags = {"vertices": ["select", "hide"],
             "edges": ["select", "hide", "use_seam", "use_edge_sharp", "use_freestyle_mark", "crease"],
             "polygons": ["select", "hide", "use_freestyle_mark"]}
    for collection, names in flags.items():
        names[:] = [name for name in names if hasattr(getattr(mesh, collection)[0], name)]
        for element in getattr(mesh, collection):
            for name in names:
                setattr(element, name, 0.5 * (rng.random() < 0.3) if name == "crease" else bool(rng.random() < 0.3))
    crease = None
    if not hasattr(mesh.edges[0], "crease"):  # Blender 4.0+
        crease = (rng.random(len(mesh.edges)) < 0.3).astype(np.float32) * 0.5
        mesh.attributes.new("crease_edge", "FLOAT", "EDGE").data.foreach_set("value", crease)

    def key(collection, element):
        return element.index if collection == "vertices" else tuple(sorted(element.vertices[:]))

    def table(m, collection):
        return {key(collection, e): tuple(getattr(e, name) for name in flags[collection])
                for e in getattr(m, collection)}

    def creases(m):
        values = np.empty(len(m.edges), dtype=np.float32)
        m.attributes["crease_edge"].data.foreach_get("value", values)
        return {key("edges", e): float(values[e.index]) for e in m.edges}

    before = {collection: table(mesh, collection) for collection in flags}
    crease_before = creases(mesh) if crease is not None else None
    assert bpy.ops.topstoc.fill_holes(mode="ALL") == {"FINISHED"}
    out = obj.data
    assert len(out.polygons) > len(mesh.polygons) - 1 and len(out.vertices) >= len(vertices)
    for collection in flags:
        after = {k: v for k, v in table(out, collection).items() if k in before[collection]}
        wrong = [(k, before[collection][k], v) for k, v in after.items() if before[collection][k] != v]
        assert len(after) == len(before[collection]) and not wrong, (collection, wrong[:5], len(wrong))
    if crease is not None:
        after = creases(out)
        assert all(after[k] == v for k, v in crease_before.items()) and max(after.values()) == 0.5
