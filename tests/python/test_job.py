"""The decimation job (core/api/job.py): every parameter resolved and checked once, when the job is
made; the public decimate is a thin adapter that gives the same result as running the job."""

import dataclasses

import numpy as np
import pytest

from topstoc.core import Mesh, read_mesh
from topstoc.core.api import job as job_module
from topstoc.core.api.decimate import run_job
from topstoc.core.support.errors import TopStocError
from topstoc.core.api.job import QUALITY_COLLAPSES, QUALITY_REFINE, make_job

from conftest import DATA


@pytest.fixture(scope="module")
def fandisk():
    data = read_mesh(DATA / "genus0/cgal_fandisk.off")
    return Mesh(data.vertices, data.triangles)


@pytest.mark.parametrize("options, expected", [
    (dict(), ("quality", "filtered", QUALITY_REFINE, QUALITY_COLLAPSES)),
    (dict(mode="fast"), ("fast", "subsample", 0.0, 0)),
    (dict(mode="fast", refine=4), ("fast", "subsample", 4.0, 0)),
    (dict(mode="quality", placement="subsample"), ("quality", "subsample", QUALITY_REFINE, QUALITY_COLLAPSES)),
    (dict(symmetry="x"), ("quality", "subsample", QUALITY_REFINE, QUALITY_COLLAPSES)),  # mirrored: input positions
])
def test_mode_is_resolved_once(fandisk, options, expected):
    job = make_job(fandisk, ratio=0.1, **options)
    assert (job.mode, job.placement, job.refine, job.refine_collapses) == expected


def test_target_becomes_a_count(fandisk):
    active = fandisk.report().input_vertices - fandisk.report().isolated_vertices
    assert make_job(fandisk, ratio=0.1).target.vertex_count == round(0.1 * active)
    assert make_job(fandisk, target_vertices=77).target.vertex_count == 77
    triangles = make_job(fandisk, target_triangles=500).target
    assert (triangles.triangles, triangles.vertex_count) == (500, 1)
    bound = make_job(fandisk, max_error=0.01, relative=True).target
    assert (bound.max_error, bound.relative, bound.vertex_count) == (0.01, True, 0)


def test_a_job_is_frozen(fandisk):
    job = make_job(fandisk, ratio=0.1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        job.seed = 3


@pytest.mark.parametrize("options", [
    dict(ratio=0.1, seed=3),
    dict(ratio=0.05, mode="fast", density="uniform", density_rings=1),
    dict(target_triangles=800, mode="fast"),
    dict(target_vertices=300, adaptivity=0.9, flat_floor=0.1),
])
def test_decimate_is_the_job_run(fandisk, options):
    direct = fandisk.decimate(**options)
    ran = run_job(fandisk, make_job(fandisk, **options))
    for name in ("vertices", "triangles", "samples", "kept", "face_source"):
        np.testing.assert_array_equal(getattr(direct, name), getattr(ran, name))
    assert direct.parameters == ran.parameters
    assert direct.parameters["refine_collapses"] == make_job(fandisk, **options).refine_collapses


def test_guidance_is_checked_once_for_an_error_bounded_search(fandisk, monkeypatch):
    """The search re-decimates many times; the job checked the guidance when it was made, and the
    probes reuse it."""
    calls = []
    original = job_module.guidance_values
    monkeypatch.setattr(job_module, "guidance_values", lambda *a: calls.append(1) or original(*a))
    u = np.zeros(fandisk.num_vertices)
    result = fandisk.decimate(max_error=0.02, relative=True, guidance=u, mode="fast")
    assert len(result.error_bound.probes) > 2 and len(calls) == 1


@pytest.mark.parametrize("options, message", [
    (dict(ratio=0.1, guidance=np.full(4, 0.0)), "guidance must hold one value per vertex"),
    (dict(ratio=0.1, adaptivity=2.0), "adaptivity must lie in [0, 1]"),
    (dict(ratio=0.1, symmetry="w"), "symmetry axis must be one of"),
    (dict(ratio=0.1, refine=0.5), "refine must be 0 (off) or a factor of at least 1"),
    (dict(ratio=0.1, mode="finest"), "mode must be one of"),
])
def test_bad_parameters_fail_when_the_job_is_made(fandisk, options, message):
    with pytest.raises(TopStocError) as error:
        make_job(fandisk, **options)
    assert message in str(error.value)
