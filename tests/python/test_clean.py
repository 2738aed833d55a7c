"""topstoc.core.api.clean: small handles, tunnels and holes removed in one step (docs/design.md §4.6).

Genus and holes are checked with GUDHI's Betti numbers, the untouched surface by comparing
positions with the input through the result's maps, and the patches' shape with the thesis'
aspect ratio computed in tests/reference.py.
"""


import numpy as np
import pytest

import cleanup_meshes
from conftest import DATA
import cli
import meshgen
import reference
from topology_checks import gudhi_betti
from topstoc.core.api import edit
from topstoc.core.api.clean import clean
from topstoc.core.support.errors import TopStocError
from topstoc.core.api.loops import self_intersections


def genus(vertices, triangles):
    """Genus of a closed connected orientable surface from GUDHI: beta1 / 2."""
    betti = gudhi_betti(len(vertices), triangles)
    assert betti[0] == 1 and betti[2] == 1, betti
    return betti[1] // 2


def patch_aspect(result):
    """Worst aspect ratio over the triangles the clean-up created."""
    created = result.edit.face_source < 0
    return reference.aspect_ratios(result.vertices, result.triangles[created]).max()


def assert_rest_unchanged(vertices, triangles, result):
    """Every input triangle is still there with the same corners; one whose positions changed
    touches a patch border (a copy of a cut loop, the only vertices a removal moves)."""
    e = result.edit
    kept = e.face_source >= 0
    assert np.array_equal(np.sort(e.face_source[kept]), np.arange(len(triangles)))
    assert np.array_equal(e.vertex_source[e.triangles[kept]], triangles[e.face_source[kept]])
    same = np.all(e.vertices[e.triangles[kept]] == vertices[triangles[e.face_source[kept]]], axis=(1, 2))
    border = np.zeros(e.num_vertices, dtype=bool)
    for patch in e.patches:
        border[patch.boundary] = True
    moved = ~same
    assert not (moved & ~border[e.triangles[kept]].any(axis=1)).any()
    return int(moved.sum())


@pytest.mark.parametrize("small,large,seed", [(6, 2, 1), (20, 1, 2)])
def test_small_handles_go_large_ones_stay(small, large, seed):
    vertices, triangles = cleanup_meshes.block_with_arches(small, large, jitter=0.05, seed=seed)
    assert genus(vertices, triangles) == small + large
    result = clean(vertices, triangles, max_handle=6.0, max_hole=0)
    assert genus(result.vertices, result.triangles) == large
    assert (result.genus_before, result.genus_after) == (small + large, large)
    assert result.count("handle") + result.count("tunnel") == small and result.count("hole") == 0
    # Unit arches: the shorter loop (handle or tunnel) is 4 edges, about 4 long.
    assert all(item.edges == 4 and 3.5 < item.loop_length < 4.5 for item in result.removed)
    # Each large handle leaves its handle and its tunnel loop, both about 12 long, above the size.
    assert len(result.left) == 2 * large
    assert all(item.loop_length > 6 and "not below the size" in item.reason for item in result.left)
    assert len(self_intersections(result.vertices, result.triangles)) == 0
    assert patch_aspect(result) <= 5
    assert result.patch_aspect == pytest.approx(patch_aspect(result))
    moved = assert_rest_unchanged(vertices, triangles, result)
    assert 0 < moved <= sum(3 * 2 * item.edges for item in result.removed)


def test_smooth_little_handles_get_faired_caps():
    vertices, triangles = cleanup_meshes.block_with_arches(8, 1)
    vertices, triangles = meshgen.subdivide(vertices, triangles, 1)
    vertices = cleanup_meshes.smoothed(vertices, triangles)
    assert len(self_intersections(vertices, triangles)) == 0 and genus(vertices, triangles) == 9
    result = clean(vertices, triangles, max_handle=5.0)  # smoothed unit arches' loops: about 3.2
    assert genus(result.vertices, result.triangles) == 1
    assert result.count("handle") + result.count("tunnel") == 8
    assert {item.patch for item in result.removed} == {"faired"}
    assert np.count_nonzero(result.edit.vertex_source < 0) > 0  # refined: the caps have inner vertices
    assert len(self_intersections(result.vertices, result.triangles)) == 0
    assert patch_aspect(result) <= 5
    assert_rest_unchanged(vertices, triangles, result)


def test_large_handle_gets_flat_patch_when_faired_caps_cross():
    # A thick handle (4 x 4): faired caps continue the tube and bulge into each other, so the
    # clean-up falls back to refined flat caps instead of leaving the handle.
    vertices, triangles = cleanup_meshes.block_with_arches(2, 1, large_size=4, jitter=0.05, seed=3)
    result = clean(vertices, triangles, max_handle=20.0)
    assert genus(result.vertices, result.triangles) == 0
    assert result.left == []
    big = [item for item in result.removed if item.edges == 16]
    assert len(big) == 1 and big[0].patch in ("refined", "flat")
    assert len(self_intersections(result.vertices, result.triangles)) == 0
    assert patch_aspect(result) <= 5
    assert_rest_unchanged(vertices, triangles, result)


def test_keep_largest():
    vertices, triangles = cleanup_meshes.block_with_arches(5, 2, jitter=0.05, seed=4)
    result = clean(vertices, triangles, keep_largest=2)
    assert genus(result.vertices, result.triangles) == 2
    assert result.count("handle") + result.count("tunnel") == 5
    assert max(item.loop_length for item in result.removed) < min(item.loop_length for item in result.left)
    assert all("largest" in item.reason for item in result.left)
    both = clean(vertices, triangles, keep_largest=6, max_handle=6.0)  # keep_largest binds first
    assert genus(both.vertices, both.triangles) == 6


def test_small_holes_filled_large_ones_left():
    vertices, triangles = cleanup_meshes.perforated_plate(25, 3, jitter=0.05, seed=5)
    assert gudhi_betti(len(vertices), triangles)[1] == 28  # a disk with 28 holes
    result = clean(vertices, triangles, max_hole=6.0)
    assert gudhi_betti(len(result.vertices), result.triangles)[1] == 3
    holes = edit.boundary_loops(result.vertices, result.triangles)
    perimeters = sorted(len(h) for h in holes)
    assert perimeters == [16, 16, 16, 160]
    assert result.count("hole") == 25 and all(item.edges == 4 for item in result.removed)
    assert sorted(item.loop_length > 6 for item in result.left if item.kind == "hole") == [True] * 4
    assert any(item.kind == "component" and "open" in item.reason for item in result.left)
    assert patch_aspect(result) <= 5
    assert_rest_unchanged(vertices, triangles, result)
    assert np.array_equal(result.vertices[:len(vertices)], vertices)  # filling moves nothing


def test_larger_holes_are_refined_into_the_surface():
    vertices, triangles = cleanup_meshes.perforated_plate(0, 3, jitter=0.05, seed=6)
    result = clean(vertices, triangles, max_hole=20.0)
    assert result.count("hole") == 3
    assert np.count_nonzero(result.edit.vertex_source < 0) >= 3 * 4  # refined: 3 x 3 inner vertices or so
    assert patch_aspect(result) <= 5
    # Edge lengths of the patches match the plate's (unit quads: 1 and 1.41).
    created = result.triangles[result.edit.face_source < 0]
    p = result.vertices[created]
    lengths = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2)
    assert 0.5 < lengths.mean() < 1.6


def test_attributes_follow_the_composed_maps():
    vertices, triangles = cleanup_meshes.block_with_arches(4, 0, jitter=0.05, seed=7)
    result = clean(vertices, triangles, max_handle=6.0)
    corner_ids = np.arange(3 * len(triangles)).reshape(-1, 3)
    carried = result.edit.corner_attribute(corner_ids)
    kept = result.edit.face_source >= 0
    assert np.array_equal(carried[kept], corner_ids[result.edit.face_source[kept]])
    colours = np.random.default_rng(0).random((len(vertices), 3))
    out = result.edit.vertex_attribute(colours)
    old = result.edit.vertex_source >= 0
    assert np.array_equal(out[old], colours[result.edit.vertex_source[old]])
    assert len(result.edit.patches) == 2 * 4  # two caps per removal, tagged with their report entry
    assert sorted({p.hole for p in result.edit.patches}) == list(range(4))


def test_sizes_relative_to_the_diagonal_and_zero():
    vertices, triangles = cleanup_meshes.block_with_arches(3, 0, jitter=0.05, seed=8)
    diagonal = np.linalg.norm(np.ptp(vertices, axis=0))
    assert clean(vertices, triangles).max_handle == pytest.approx(0.01 * diagonal)
    # 4-long loops are about 27 % of this block's diagonal.
    assert clean(vertices, triangles, max_handle="20%").genus_after == 3
    assert clean(vertices, triangles, max_handle="35%").genus_after == 0
    nothing = clean(vertices, triangles, max_handle=0, max_hole=0)
    assert np.array_equal(nothing.vertices, vertices) and np.array_equal(nothing.triangles, triangles)
    assert nothing.removed == [] and nothing.rounds == 0
    for bad in ("big", -1.0, "-2%", [1]):
        with pytest.raises(TopStocError):
            clean(vertices, triangles, max_handle=bad)
    with pytest.raises(TopStocError):
        clean(vertices, triangles, keep_largest=-1)


def test_cli_clean(tmp_path):
    from topstoc.core.api.io import MeshData, read_mesh, write_mesh

    vertices, triangles = cleanup_meshes.block_with_arches(3, 1, jitter=0.05, seed=9)
    source, target = tmp_path / "in.obj", tmp_path / "out.ply"
    write_mesh(str(source), MeshData(vertices=vertices, triangles=triangles))
    before = source.read_bytes()
    report = cli.run_json("clean", source, target, "--max-handle", "6")
    assert report["clean"]["genus_before"] == 4 and report["clean"]["genus_after"] == 1
    assert report["clean"]["handles_removed"] == 3 and len(report["clean"]["left"]) == 2
    assert report["summary"] == "1 component: genus 1, closed, orientable"
    out = read_mesh(str(target))
    assert genus(out.vertices, out.triangles) == 1
    assert source.read_bytes() == before
    done = cli.run("clean", source, target, "--max-handle", "6")
    assert done.returncode == 0 and "removed 3 handles" in done.stdout and done.stdout.count("  left ") == 2
    cli.assert_one_error_line("clean", cli.run("clean", source, target, "--max-hole", "x"), "max_hole")
    cli.assert_one_error_line("clean", cli.run("clean", source, target, "--keep-largest", "-1"), "--keep-largest")
    cli.assert_one_error_line("clean", cli.run("clean", source, source), "in.obj")  # never over the input
    assert source.read_bytes() == before
    every = cli.run_json("clean", source, target, "--keep-largest", "0", "--flat")["clean"]
    assert every["genus_after"] == 0 and every["handles_removed"] == 4
    assert {item["patch"] for item in every["removed"]} == {"flat"}


def test_local_removal_is_the_whole_mesh_edit(monkeypatch):
    from topstoc.core.api import local_edit
    from topstoc.core.api.local_edit import LocalEditor
    from topstoc.core.api.loops import handle_tunnel_loops

    vertices, triangles = cleanup_meshes.block_with_arches(30, 0, jitter=0.05, seed=10)
    loop = min(handle_tunnel_loops(vertices, triangles).handles, key=lambda loop: loop.length).vertices
    whole = edit.remove_handle(vertices, triangles, loop, refine=True, fair=True)
    editor = LocalEditor(vertices, triangles)
    sizes = []
    original = edit.remove_handle

    def recording(v, t, *args, **kwargs):
        sizes.append(len(t))
        return original(v, t, *args, **kwargs)

    monkeypatch.setattr(local_edit.edit, "remove_handle", recording)
    editor.remove_handle(loop, 0, refine=True, fair=True)
    local = editor.result()
    assert len(sizes) == 1 and sizes[0] < len(triangles) / 4  # edited on a neighbourhood
    for name in ("vertices", "triangles", "vertex_source", "face_source", "corner_source"):
        assert np.array_equal(getattr(local, name), getattr(whole, name)), name
    assert [p.boundary.tolist() for p in local.patches] == [p.boundary.tolist() for p in whole.patches]
    corners = local.vertices[local.triangles]
    low, high = editor.boxes()
    assert np.array_equal(low, corners.min(axis=1)) and np.array_equal(high, corners.max(axis=1))


def test_scanned_elephant_holes_and_handles(data_dir):
    from topstoc.core.api.io import read_mesh

    data = read_mesh(str(data_dir / "open_boundary" / "cgal_elephant-with-holes.off"))
    vertices, triangles = data.vertices, data.triangles
    crossings_before = len(self_intersections(vertices, triangles))
    holes = len(edit.boundary_loops(vertices, triangles))
    filled = clean(vertices, triangles, max_hole=2.0, max_handle=0)
    # Every hole filled (some borders pass twice through one point: welded, filled per lobe).
    assert filled.count("hole") == holes == 106 and edit.boundary_loops(filled.vertices, filled.triangles) == []
    assert genus(filled.vertices, filled.triangles) == 3
    assert patch_aspect(filled) <= 5
    pairs = np.asarray(self_intersections(filled.vertices, filled.triangles))
    created = filled.edit.face_source < 0
    assert not created[pairs].any() and len(pairs) <= crossings_before
    # Its three handles are small defects (loops about 8 % of the diagonal, 7-8 edges).
    result = clean(vertices, triangles, max_hole=2.0, max_handle="20%")
    assert genus(result.vertices, result.triangles) == 0
    assert result.count("handle") + result.count("tunnel") == 3 and result.left == []
    assert patch_aspect(result) <= 5
    pairs = np.asarray(self_intersections(result.vertices, result.triangles))
    assert not (result.edit.face_source < 0)[pairs].any()


def test_a_failed_removal_is_reported_not_retried(monkeypatch):
    from topstoc.core.api import local_edit

    vertices, triangles = cleanup_meshes.block_with_arches(3, 1, jitter=0.05, seed=13)
    calls = []

    def refuse(v, t, loop, **options):
        calls.append(options["fair"])
        raise TopStocError("removing the handle along this loop would make the surface intersect itself")

    monkeypatch.setattr(local_edit.edit, "remove_handle", refuse)
    result = clean(vertices, triangles, max_handle=6.0)
    assert result.removed == [] and result.genus_after == 4 and result.rounds == 0
    failed = [item for item in result.left if item.reason.startswith("removal failed")]
    assert len(failed) == 6 and all(item.loop_length < 6 for item in failed)  # both loops of each small arch
    assert sum(item.loop_length >= 6 for item in result.left) == 2
    assert calls == [True] * 6  # once per loop (stepping down to flatter patches inside), never again


def test_a_hole_whose_patch_would_cross_the_surface_stays_open():
    from topstoc.core.api.clean import crossing_patches

    vertices, triangles = cleanup_meshes.perforated_plate(2, 0, side=12, seed=14)
    holes = edit.boundary_loops(vertices, triangles)
    small = [i for i, h in enumerate(holes) if len(h) == 4]
    pierced = holes[small[0]].vertices
    centre = vertices[pierced].mean(axis=0)
    # A separate triangle standing through the first hole: any patch of it crosses the triangle.
    spike = centre + np.array([[-0.3, 0.0, -1.0], [0.3, 0.0, -1.0], [0.0, 0.0, 1.0]])
    vertices = np.concatenate([vertices, spike])
    triangles = np.concatenate([triangles, [[len(vertices) - 3, len(vertices) - 2, len(vertices) - 1]]])
    result = clean(vertices, triangles, max_hole=6.0, max_handle=0)
    assert result.count("hole") == 1
    crossing = [item for item in result.left if item.reason == "every patch tried crosses the surface"]
    assert len(crossing) == 1 and sorted(crossing[0].vertices) == sorted(pierced)
    assert len(edit.boundary_loops(result.vertices, result.triangles)) == len(holes) - 1 + 1  # + the spike's
    assert len(self_intersections(result.vertices, result.triangles)) == 0
    # The local test finds what a whole-mesh test finds.
    both = edit.fill_holes(vertices, triangles, holes=small)
    pairs = np.asarray(self_intersections(both.vertices, both.triangles))
    owner = np.full(both.num_triangles, -1)
    for patch in both.patches:
        owner[patch.triangles] = patch.hole
    assert crossing_patches(both) == set(owner[pairs.reshape(-1)].tolist()) - {-1} == {small[0]}


def test_cli_lists_handles_first_and_shortens_long_lists(tmp_path):
    from topstoc.core.cli.clean import SHOWN
    from topstoc.core.api.io import MeshData, write_mesh

    vertices, triangles = cleanup_meshes.perforated_plate(SHOWN + 10, 1, side=40, seed=15)
    source = tmp_path / "plate.obj"
    write_mesh(str(source), MeshData(vertices=vertices, triangles=triangles))
    done = cli.run("clean", source, tmp_path / "out.obj", "--max-hole", "6")
    assert done.returncode == 0, done.stderr
    items = [line for line in done.stdout.splitlines() if line.startswith(("  removed ", "  left "))][1:]
    assert len(items) == SHOWN and items[0].startswith("  left hole")  # the large holes come before the filled
    # SHOWN + 10 filled, 3 left (the large hole, the plate's edge, the open component): 13 not shown
    assert done.stdout.splitlines()[-1] == "  ... and 13 more (--json lists every one)"


def test_a_round_of_local_removals_is_the_chain_of_whole_mesh_edits():
    """Several removals written in place by one LocalEditor give the arrays, maps and patches of
    the same removals done one after another on the whole mesh and composed (clean.compose)."""
    from topstoc.core.api.clean import compose, identity
    from topstoc.core.api.local_edit import LocalEditor
    from topstoc.core.api.loops import handle_tunnel_loops

    vertices, triangles = cleanup_meshes.block_with_arches(12, 0, jitter=0.05, seed=4)
    loops, used = [], set()
    for loop in sorted(handle_tunnel_loops(vertices, triangles).handles, key=lambda loop: loop.length):
        if not used & set(loop.vertices.tolist()):
            loops.append(loop.vertices)
            used |= set(loop.vertices.tolist())
    assert len(loops) >= 4
    editor = LocalEditor(vertices, triangles)
    chain = identity(vertices, triangles)
    for tag, loop in enumerate(loops):
        editor.remove_handle(loop, tag, refine=True, fair=True)
        chain = compose(chain, edit.remove_handle(chain.vertices, chain.triangles, loop, refine=True, fair=True), tag)
    local = editor.result()
    for name in ("vertices", "triangles", "vertex_source", "face_source", "corner_source"):
        assert np.array_equal(getattr(local, name), getattr(chain, name)), name
    assert [(p.hole, p.boundary.tolist(), p.triangles, p.vertices) for p in local.patches] == \
        [(p.hole, p.boundary.tolist(), p.triangles, p.vertices) for p in chain.patches]
    low, high = editor.boxes()
    corners = local.vertices[local.triangles]
    assert np.array_equal(low, corners.min(axis=1)) and np.array_equal(high, corners.max(axis=1))


def test_a_non_manifold_component_is_left_and_the_others_cleaned():
    """One non-manifold component used to stop the loops of the whole mesh (no handle removed
    anywhere); now it is reported and left bit for bit, and the other component is cleaned."""
    from topstoc.core.api.component_loops import loops_by_component
    from topstoc.core.api.loops import handle_tunnel_loops

    block, block_triangles = cleanup_meshes.block_with_arches(2, 0, jitter=0.05, seed=5)
    fin, fin_triangles = meshgen.tetrahedra_sharing_edge()  # four triangles on one edge
    n, m = len(block), len(block_triangles)
    vertices = np.vstack([block, fin + [0.0, 0.0, 20.0]])
    triangles = np.vstack([block_triangles, fin_triangles + n]).astype(np.int32)
    with pytest.raises(ValueError, match="non-manifold"):
        handle_tunnel_loops(vertices, triangles)

    found = loops_by_component(vertices, triangles)
    assert [c.status for c in found.components] == ["ok", "refused"]
    assert "edge 0-1" not in found.components[1].detail and f"edge {n}-{n + 1}" in found.components[1].detail
    alone = handle_tunnel_loops(block, block_triangles)  # the block's loops, in its own ids = the whole's
    assert [loop.vertices.tolist() for loop in found.components[0].loops] == \
        [loop.vertices.tolist() for loop in alone.components[0].loops]

    result = clean(vertices, triangles, max_handle=6.0)
    assert result.count("handle") + result.count("tunnel") == 2 and result.count("hole") == 0
    e = result.edit
    cleaned_block = np.isin(e.face_source, np.arange(m)) | (e.face_source < 0)
    assert genus(e.vertices, e.triangles[cleaned_block]) == 0
    [left] = result.left
    assert left.kind == "component" and left.vertices.tolist() == [n]
    assert left.reason.startswith("component 1 left as is: non-manifold: 1 edges have three or more triangles")
    # The fin: the same triangles on the same vertex ids, at the same positions bit for bit.
    rows = np.flatnonzero(e.face_source >= m)
    assert np.array_equal(e.face_source[rows], np.arange(m, m + len(fin_triangles)))
    assert np.array_equal(e.triangles[rows], triangles[m:])
    assert e.vertices[n:n + len(fin)].tobytes() == vertices[n:].tobytes()


@pytest.fixture(scope="module")
def pinched_scan():
    """The armadillo scan with 8 pinched handles (bench_cleanup --scan), cleaned at 1 %:
    (vertices, triangles, result)."""
    from topstoc.core.api.io import read_mesh

    data = read_mesh(str(DATA / "genus0" / "cgal_armadillo.off.gz"))
    vertices, triangles, _arches = cleanup_meshes.with_pinched_handles(data.vertices, data.triangles, 8, seed=1)
    return vertices, triangles, clean(vertices, triangles, max_handle="1%", max_hole=0)


@pytest.mark.heavy
def test_no_handle_below_the_size_is_left_after_its_neighbours_go(pinched_scan):
    """The armadillo scan with 8 pinched handles at 1 %: removing the short loops can make a
    longer loop of a handle left shorter than the size (it no longer depends on them), so every
    round after a removal computes the loops again; a fresh computation on the output finds no
    handle or tunnel loop below the size."""
    from topstoc.core.api.loops import handle_tunnel_loops

    vertices, triangles, result = pinched_scan
    size = 0.01 * float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    again = handle_tunnel_loops(result.vertices, result.triangles)
    assert min((loop.length for loop in again.handles + again.tunnels), default=np.inf) >= size
    assert genus(result.vertices, result.triangles) == result.genus_after == len(again.handles)
    assert all("not below the size" in item.reason for item in result.left if item.kind in ("handle", "tunnel"))


def test_caps_of_pinched_handles_are_no_slivers(pinched_scan):
    """The pinched handles' loops are 3 edges shorter than the scan's edges, and pulling the
    loop's copies apart makes some copies slivers (aspect up to 15.6): a faired cap that was the
    copy's own triangle now has a vertex lifted off it, and every cap is within aspect 5."""
    vertices, triangles, result = pinched_scan
    e = result.edit
    assert result.count("handle") + result.count("tunnel") == 7
    caps = [p for p in e.patches if len(p.boundary) == 3]
    assert len(caps) == 14 and all(p.faired for p in caps)
    own = reference.aspect_ratios(e.vertices, np.array([p.boundary for p in caps]))
    lifted = [p for p, a in zip(caps, own) if a > 5]
    assert len(lifted) >= 3  # the copies that are slivers: each has a vertex of its own now
    assert all(p.vertices.stop - p.vertices.start == 1 and p.triangles.stop - p.triangles.start == 3
               for p in lifted)
    assert patch_aspect(result) <= 5
    assert max(item.patch_aspect for item in result.removed) == pytest.approx(patch_aspect(result))
    assert len(self_intersections(result.vertices, result.triangles)) == 0
    assert_rest_unchanged(vertices, triangles, result)

