"""Re-decimation from a kept flood (native flood_cache.hpp): a decimation at a target near an
earlier one (same mesh, layout and seed, the slider's case) updates that decimation's flood
instead of flooding afresh. The promise is the same mesh as a fresh decimation, so every test
compares against the mesh made with ``keep_floods=False`` (nothing kept, every flood fresh),
array for array, and checks that the update really ran (``stats.flood_updated``).
"""

import math
import pathlib
import sys
import threading

import numpy as np
import pytest

import meshgen
import reference
from topstoc.core import Mesh

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import random_manifolds  # noqa: E402

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
FIELDS = ("vertices", "triangles", "kept", "face_source", "corner_source", "labels", "samples")


def load(path):
    return Mesh(*reference.read_off(path))


def assert_same(a, b):
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.stats.issues_found == b.stats.issues_found
    assert (a.stats.repairs, a.stats.top_up) == (b.stats.repairs, b.stats.top_up)


def fresh(mesh, **options):
    """The same decimation on a copy of the mesh that keeps no flood."""
    plain = Mesh(mesh.vertices, mesh.triangles, keep_floods=False)
    result = plain.decimate(**options)
    assert not result.stats.flood_updated
    return result


def slider(start, steps, step):
    """Ratios a drag passes: up from start, then back down past it."""
    up = [start * (1 + step * i) for i in range(steps)]
    return up + up[::-1][1:] + [start * (1 - step * i) for i in range(1, steps)]


def check_slider(mesh, steps=6, step=0.02, **options):
    """Decimates along a drag with the kept floods and fresh; returns how many were updates."""
    start = options.pop("ratio")
    updated = 0
    for ratio in slider(start, steps, step):
        mesh.decimate(ratio=ratio * (1 - step), **options)  # the kept flood: a step before
        got = mesh.decimate(ratio=ratio, **options)
        updated += got.stats.flood_updated
        assert_same(got, fresh(mesh, ratio=ratio, **options))
    return updated


CASES = {
    "dragon, fast": ("genus0/cgal_ChineseDragon-10kv.off", dict(mode="fast", ratio=0.1, seed=3)),
    "dragon, fast, 2 %": ("genus0/cgal_ChineseDragon-10kv.off", dict(mode="fast", ratio=0.02, seed=5)),
    "3-torus, quality": ("genus_positive/cgal_3torus.off", dict(ratio=0.1, seed=1)),
    "elephant with holes, fast": ("open_boundary/cgal_elephant-with-holes.off", dict(mode="fast", ratio=0.05, seed=2)),
    "fandisk, creases": ("genus0/cgal_fandisk.off", dict(mode="fast", ratio=0.15, seed=4,
                                                         feature_angle=math.radians(40))),
    "turbine": ("genus_positive/cgal_turbine.off", dict(mode="fast", ratio=0.03, seed=6)),
}


@pytest.mark.parametrize("case", CASES, ids=str)
def test_nearby_targets_give_the_fresh_result(case):
    path, options = CASES[case]
    updated = check_slider(load(DATA / path), **options)
    assert updated >= 5  # the floods were really updated (a far first step may flood afresh)


def test_regions_guidance_and_triangle_targets():
    v, t = meshgen.icosphere(5)
    centroid = v[t].mean(axis=1)
    regions = (centroid[:, 0] > 0.2).astype(np.int32) + 2 * (centroid[:, 1] > -0.3)
    guidance = np.clip(v[:, 2], -0.9, 0.9)  # denser towards +z, sparser towards -z
    mesh = Mesh(v, t)
    assert check_slider(mesh, mode="fast", ratio=0.08, seed=2, regions=regions, guidance=guidance) >= 5
    for i, triangles in enumerate((800, 820, 840, 820, 800, 780)):
        got = mesh.decimate(mode="fast", target_triangles=triangles, seed=2, regions=regions)
        assert got.stats.flood_updated == (i > 0)  # the first follows draws with guidance
        assert_same(got, fresh(mesh, mode="fast", target_triangles=triangles, seed=2, regions=regions))


def test_another_seed_a_far_lower_target_or_the_fast_path_floods_afresh():
    mesh = load(DATA / "genus0/cgal_ChineseDragon-10kv.off")
    mesh.decimate(mode="fast", ratio=0.2, seed=1)
    assert not mesh.decimate(mode="fast", ratio=0.2, seed=2).stats.flood_updated
    # half the samples removed: refilling their clusters costs more than a fresh flood
    assert not mesh.decimate(mode="fast", ratio=0.1, seed=2).stats.flood_updated
    # twice the samples: the added ones take their share of the kept clusters
    assert mesh.decimate(mode="fast", ratio=0.2, seed=2).stats.flood_updated
    assert mesh.decimate(mode="fast", ratio=0.202, seed=2).stats.flood_updated
    # the fast path's candidate faces can miss one a full scan finds: it never updates
    assert not mesh.decimate(mode="fast", ratio=0.204, seed=2, fast_path=True).stats.flood_updated


def test_threads_sharing_a_mesh_get_the_fresh_results():
    """The preview's workers decimate one mesh side by side: each takes a kept flood of its own
    (two per layout), and every result is still the fresh one."""
    mesh = load(DATA / "genus_positive/cgal_elephant.off")
    ratios = slider(0.1, 8, 0.01)
    expected = {r: fresh(mesh, mode="fast", ratio=r, seed=7) for r in ratios}
    results, errors = {}, []

    def drag(offset):
        try:
            for ratio in ratios[offset:] + ratios[:offset]:
                results[(offset, ratio)] = mesh.decimate(mode="fast", ratio=ratio, seed=7)
        except Exception as error:  # noqa: BLE001 - reported below
            errors.append(error)

    workers = [threading.Thread(target=drag, args=(offset,)) for offset in (0, 3, 5)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join()
    assert not errors
    for (_offset, ratio), got in results.items():
        assert_same(got, expected[ratio])
    assert sum(got.stats.flood_updated for got in results.values()) > len(results) // 2
    _layout, floods = mesh.layout_and_floods()
    assert 1 <= floods.size <= 2  # three threads, at most two kept floods (two only if they overlapped)
    mesh.clear_floods()
    assert floods.size == 0


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.heavy
def test_random_manifolds_and_pinched_surfaces(seed):
    """Random hulls, tori, grids with holes, several components, and surfaces glued at vertices
    (tests/random_manifolds.py): a drag of 12 steps gives the fresh results."""
    vertices, triangles, ratios, rng = random_manifolds.drag_case(seed)
    mesh, plain = Mesh(vertices, triangles), Mesh(vertices, triangles, keep_floods=False)
    updated = 0
    for ratio in ratios:
        options = dict(mode=str(rng.choice(["fast", "quality"])), ratio=ratio, seed=seed)
        got = mesh.decimate(**options)
        updated += got.stats.flood_updated
        assert_same(got, plain.decimate(**options))
    assert updated > 0


def test_a_pool_never_serves_another_mesh_or_layout():
    """Kept floods are told apart by the mesh's and layout's serial numbers, not addresses: one
    pool used (through the engine) for another mesh, or another layout, floods afresh."""
    from topstoc.core.api.job import make_job
    from topstoc.core.support.native import engine
    dragon = load(DATA / "genus0/cgal_ChineseDragon-10kv.off")
    other = Mesh(dragon.vertices * 2.0, dragon.triangles)  # same size, other mesh
    pool = engine.FloodCachePool()
    plain, creased = dragon.feature_layout(), dragon.feature_layout(feature_angle=0.5)

    def run(mesh, layout, target):
        job = make_job(mesh, target_vertices=target, seed=1, mode="fast")  # plain TopStoc, as the engine's defaults
        return engine.decimate(mesh.native, layout, job, flood_caches=pool)["flood_updated"]

    assert not run(dragon, plain, 1000)
    assert run(dragon, plain, 1010)
    assert not run(other, other.feature_layout(), 1020)
    assert not run(dragon, creased, 1030)
    assert pool.size == 1  # one thread: the same cache each time, refilled


def test_cleared_layouts_are_built_again_with_the_same_results():
    """clear_layouts (a one-shot job frees its layout, sampling tables and floods) drops the
    cached layout; the next decimations build a new one and give the same results bit for bit."""
    vertices, triangles = meshgen.torus(48, 24)
    mesh = Mesh(vertices, triangles)
    before = [mesh.decimate(ratio=ratio, seed=2, mode=mode) for ratio, mode in ((0.2, "quality"), (0.1, "fast"))]
    layout = mesh.feature_layout()
    mesh.clear_layouts()
    assert mesh.feature_layout() is not layout
    mesh.clear_layouts()
    after = [mesh.decimate(ratio=ratio, seed=2, mode=mode) for ratio, mode in ((0.2, "quality"), (0.1, "fast"))]
    for old, new in zip(before, after):
        np.testing.assert_array_equal(old.vertices, new.vertices)
        np.testing.assert_array_equal(old.triangles, new.triangles)
        np.testing.assert_array_equal(old.samples, new.samples)


@pytest.mark.heavy
def test_meshes_from_the_size_limit_up_keep_floods_from_a_second_decimation(monkeypatch):
    """By default a mesh keeps floods below Mesh.KEEP_FLOODS_BELOW triangles; above, from its
    layout's second decimation on (a one-off decimation's flood and the draw's tables would sit
    under the next one's peak; a slider's pay for themselves). True keeps them from the first,
    False never. Kept or not, the nearby re-decimations give the same mesh."""
    vertices, triangles = meshgen.bumpy_torus(20_000)
    count = Mesh(vertices, triangles).num_triangles
    monkeypatch.setattr(Mesh, "KEEP_FLOODS_BELOW", count)
    big, asked = Mesh(vertices, triangles), Mesh(vertices, triangles, keep_floods=True)
    never = Mesh(vertices, triangles, keep_floods=False)
    updated = []
    for ratio in (0.05, 0.048, 0.046):
        once, slider, plain = (m.decimate(ratio=ratio, seed=2) for m in (big, asked, never))
        assert_same(once, slider)
        assert_same(once, plain)
        updated.append((once.stats.flood_updated, slider.stats.flood_updated, plain.stats.flood_updated))
        if ratio == 0.05:
            assert big._layouts[next(iter(big._layouts))][1] is None  # the one-off keeps nothing
    assert never.layout_and_floods()[1] is None and asked.layout_and_floods()[1] is not None
    monkeypatch.setattr(Mesh, "KEEP_FLOODS_BELOW", count + 1)
    assert Mesh(vertices, triangles).layout_and_floods()[1] is not None
    # big: nothing kept by the first decimation, kept by the second, so the third updates it
    assert updated == [(False, False, False), (False, True, False), (True, True, False)]
