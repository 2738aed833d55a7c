"""Cancelling a decimation (run_job's ``cancel``, what the Live Preview's speculation uses): a set
CancelFlag raises Cancelled, one left unset changes nothing, and a cancelled call leaves the
mesh's kept floods and layout as good as before (the next decimation is the same)."""

import threading

import numpy as np
import pytest

import meshgen
from topstoc.core import Mesh
from topstoc.core.api.decimate import CancelFlag, run_job
from topstoc.core.api.job import make_job
from topstoc.core.api.loops import Cancelled


@pytest.fixture(scope="module")
def torus():
    mesh = Mesh(*meshgen.torus(96, 48))
    mesh.feature_layout()
    return mesh


def same(a, b):
    return all(np.array_equal(np.asarray(getattr(a, name)), np.asarray(getattr(b, name)))
               for name in ("vertices", "triangles", "samples", "kept"))


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_a_set_flag_raises_cancelled_and_an_unset_one_changes_nothing(torus, mode):
    job = make_job(torus, ratio=0.1, seed=3, mode=mode)
    plain = run_job(torus, job)
    flag = CancelFlag()
    assert not flag.is_set
    assert same(run_job(torus, job, cancel=flag), plain)
    flag.set()
    assert flag.is_set
    with pytest.raises(Cancelled):
        run_job(torus, job, cancel=flag)
    assert same(run_job(torus, job), plain)  # nothing left behind by the cancelled call


def test_a_flag_set_from_another_thread_stops_the_run(torus):
    """Set while the whole-mesh quality refinement runs (or before it starts: either way the run
    ends with Cancelled, never with a result)."""
    job = make_job(torus, ratio=0.05, seed=3, mode="quality")
    flag, outcome = CancelFlag(), []
    started = threading.Event()

    def run():
        started.set()
        try:
            outcome.append(run_job(torus, job, cancel=flag))
        except Cancelled as error:
            outcome.append(error)

    worker = threading.Thread(target=run)
    worker.start()
    started.wait()
    flag.set()
    worker.join(60)
    assert len(outcome) == 1 and isinstance(outcome[0], Cancelled)
