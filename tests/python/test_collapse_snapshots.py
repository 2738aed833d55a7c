"""Collapse states kept between quality decimations (native collapse_snapshots.hpp): a mesh
collapsed whole goes the same way toward every vertex target until its batches start to depend
on the target, so a decimation toward a lower target resumes from the state an earlier one kept
there. The promise is the same mesh as a fresh decimation: every result is compared, array for
array and figure for figure, with the same decimation of a mesh that keeps nothing
(``keep_floods=False``), and the states are checked to be kept where they apply and not elsewhere.
The input's search structure the fit of small results measures against is kept with them too.
"""

import numpy as np
import pytest

import meshgen
from topstoc.core import Mesh

FIELDS = ("vertices", "triangles", "kept", "face_source", "corner_source", "labels", "samples")


@pytest.fixture(scope="module")
def torus():
    return meshgen.bumpy_torus(20000)  # 10k vertices: collapsed whole, in batches


def assert_same(a, b):
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.stats.refine_collapses == b.stats.refine_collapses


def kept(mesh):
    return mesh.kept_for_reuse()[2].size


@pytest.mark.heavy
def test_a_drag_down_and_back_up_gives_the_fresh_results(torus):
    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    assert plain.kept_for_reuse()[2] is None
    for ratio in (0.1, 0.06, 0.03, 0.01, 0.02, 0.08, 0.1, 0.005):
        assert_same(mesh.decimate(ratio=ratio), plain.decimate(ratio=ratio))
        assert 1 <= kept(mesh) <= 2
    mesh.clear_floods()
    assert kept(mesh) == 0


@pytest.mark.heavy
def test_attributes_and_seeds_keep_their_own_states(torus):
    vertices, triangles = torus
    uv = np.stack([vertices[:, 0], vertices[:, 1]], axis=1)[triangles]  # per corner
    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    for options in (dict(ratio=0.05), dict(ratio=0.05, attributes=uv), dict(ratio=0.03, attributes=uv),
                    dict(ratio=0.03, seed=5), dict(ratio=0.02)):
        assert_same(mesh.decimate(**options), plain.decimate(**options))


def test_guided_and_triangle_targets_keep_no_state(torus):
    vertices, _ = torus
    guidance = np.where(vertices[:, 2] > 0, 0.5, 0.0)
    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    assert_same(mesh.decimate(ratio=0.05, guidance=guidance), plain.decimate(ratio=0.05, guidance=guidance))
    assert_same(mesh.decimate(target_triangles=900), plain.decimate(target_triangles=900))
    assert kept(mesh) == 0
    # A state kept by an unguided decimation is not taken by a guided one.
    mesh.decimate(ratio=0.05)
    assert kept(mesh) == 1
    assert_same(mesh.decimate(ratio=0.03, guidance=guidance), plain.decimate(ratio=0.03, guidance=guidance))


@pytest.mark.heavy
def test_the_fit_of_small_results_measures_against_a_kept_input(torus):
    """Results of 401-1,400 triangles are fitted to the input: its search structure is made once and
    kept with the states (one for the whole input: the distance passes' too), also where the first
    pass is not the whole mesh (refine=3), with the results of a mesh that keeps nothing."""
    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    snapshots = mesh.kept_for_reuse()[2]
    assert snapshots.surfaces == 0
    for options in (dict(ratio=0.05, refine=3), dict(ratio=0.04, refine=3), dict(ratio=0.05), dict(ratio=0.045)):
        result = mesh.decimate(**options)
        assert 401 <= len(result.triangles) <= 1400
        assert_same(result, plain.decimate(**options))
        assert snapshots.surfaces == 1
    assert plain.kept_for_reuse()[2] is None
    mesh.clear_floods()
    assert snapshots.surfaces == 0


def test_a_warm_up_is_what_the_next_decimations_resume_from(torus):
    """warm_up builds the first collapse run's state and the input surface a later decimation at
    its ratio or below resumes from: that decimation makes no surface and resumes from a kept
    state, with the results of a mesh that keeps nothing."""
    from topstoc.core.api.decimate import warm_up, run_job
    from topstoc.core.api.job import make_job

    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    snapshots = mesh.kept_for_reuse()[2]
    assert warm_up(mesh, make_job(mesh, ratio=0.1)) is True
    assert (snapshots.size, snapshots.surfaces, snapshots.resumed, snapshots.surfaces_made) == (1, 1, 0, 1)
    for ratio, resumed in ((0.1, 1), (0.07, 2)):
        assert_same(run_job(mesh, make_job(mesh, ratio=ratio)), plain.decimate(ratio=ratio))
        assert (snapshots.resumed, snapshots.surfaces_made) == (resumed, 1)
    # Above the warm-up's ratio nothing serves: the state is made from the start.
    assert_same(mesh.decimate(ratio=0.15), plain.decimate(ratio=0.15))
    assert snapshots.resumed == 2


def test_a_warm_up_keeps_nothing_where_no_decimation_would(torus):
    from topstoc.core.api.decimate import warm_up
    from topstoc.core.api.job import make_job

    vertices, _ = torus
    mesh = Mesh(*torus)
    snapshots = mesh.kept_for_reuse()[2]
    guidance = np.where(vertices[:, 2] > 0, 0.5, 0.0)
    assert warm_up(mesh, make_job(mesh, ratio=0.05, guidance=guidance)) is False
    assert warm_up(mesh, make_job(mesh, ratio=0.05, mode="fast")) is False
    assert warm_up(mesh, make_job(mesh, target_triangles=900)) is False
    assert warm_up(Mesh(*torus, keep_floods=False), make_job(mesh, ratio=0.05)) is False
    assert (snapshots.size, snapshots.surfaces_made) == (0, 0)


def test_a_cancelled_warm_up_leaves_the_results_unchanged(torus):
    from topstoc.core.api.decimate import CancelFlag, warm_up
    from topstoc.core.api.loops import Cancelled
    from topstoc.core.api.job import make_job

    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    flag = CancelFlag()
    flag.set()
    with pytest.raises(Cancelled):
        warm_up(mesh, make_job(mesh, ratio=0.1), flag)
    assert mesh.kept_for_reuse()[2].size == 0
    assert_same(mesh.decimate(ratio=0.08), plain.decimate(ratio=0.08))


def test_a_sliver_heavy_mesh_warms_up_and_resumes():
    """A UV sphere of 2,000 segments (98,002 vertices, every triangle a sliver) is collapsed whole
    (decimate.cpp, kSliverWholeVertices; above 80,000 vertices a mesh of fair triangles is not),
    so the Live Preview's warm-up keeps its state and the decimations after it resume from it,
    with the results of a mesh that keeps nothing."""
    from fan_meshes import uv_sphere
    from topstoc.core.api.decimate import warm_up
    from topstoc.core.api.job import make_job

    sphere = uv_sphere(2000)
    mesh, plain = Mesh(*sphere), Mesh(*sphere, keep_floods=False)
    snapshots = mesh.kept_for_reuse()[2]
    assert warm_up(mesh, make_job(mesh, ratio=0.1)) is True
    assert snapshots.size == 1
    for ratio, resumed in ((0.1, 1), (0.05, 2)):
        assert_same(mesh.decimate(ratio=ratio), plain.decimate(ratio=ratio))
        assert snapshots.resumed == resumed


@pytest.mark.heavy
def test_a_mesh_too_large_to_collapse_whole_warms_up_where_its_first_pass_is_fixed():
    """Above 250,000 vertices the collapses start from a first pass (decimate.cpp,
    first_pass_vertices) of 8 times the target, at most 250,000 vertices and, up to 500,000, at
    least 125,000: the same for every target of 31,250 vertices or more (up to 200,000), and here
    below 15,625. There a warm-up keeps the collapse run's state and the decimations at its ratio
    or below resume from it, with the results of a mesh that keeps nothing. In between the first
    pass grows with the target: a warm-up keeps nothing, and a decimation's state serves only a
    repeat of its own target (the same first pass). A first decimation keeps no state: a one-off's
    copy would only add to its peak. With a border the collapses weigh its planes by the target's
    spacing, so their start depends on the target and no warm-up keeps anything."""
    from topstoc.core.api.decimate import warm_up
    from topstoc.core.api.job import make_job

    torus = meshgen.bumpy_torus(540000)  # 270k vertices
    mesh, plain = Mesh(*torus), Mesh(*torus, keep_floods=False)
    fresh = {ratio: plain.decimate(ratio=ratio) for ratio in (0.3, 0.2, 0.09)}
    snapshots = mesh.kept_for_reuse()[2]
    assert_same(mesh.decimate(ratio=0.3), fresh[0.3])
    assert (snapshots.size, snapshots.resumed) == (0, 0)
    assert warm_up(mesh, make_job(mesh, ratio=0.3)) is True
    assert (snapshots.size, snapshots.resumed) == (1, 0)
    for ratio, resumed in ((0.3, 1), (0.2, 2)):
        assert_same(mesh.decimate(ratio=ratio), fresh[ratio])
        assert snapshots.resumed == resumed
    assert warm_up(mesh, make_job(mesh, ratio=0.09)) is False  # first pass 8 times the target
    for resumed in (2, 3):
        assert_same(mesh.decimate(ratio=0.09), fresh[0.09])
        assert snapshots.resumed == resumed
    holed = Mesh(torus[0], torus[1][8:])  # a hole: its border is a feature curve
    assert holed.report().boundary_edges > 0
    assert warm_up(holed, make_job(holed, ratio=0.3)) is False
