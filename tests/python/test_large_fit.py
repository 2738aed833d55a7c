"""Mode "best": quality, then results above 1,400 triangles are fitted to the input in one
least-squares round (native/src/decimate/tiny_fit.cpp, fit_large; DecimateParams::large_fit):
its normal equations solved by conjugate gradients, the move kept only where threshold walks
find the surfaces no farther apart than the max before it.

The same decimation in quality mode (the default) is the reference: with the fit, the mean must
fall by a margin and the max must not grow. Errors by topstoc.hausdorff (checked against CGAL in
test_hausdorff_peers.py).
"""

import numpy as np
import pytest

import topstoc
from topstoc.core import read_mesh
from reference import degenerate_or_duplicate, invariants
from threads import outputs_by_thread_count


def _decimate(path, mode):
    mesh = read_mesh(path)
    vertices, triangles = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    result = topstoc.Mesh(vertices, triangles).decimate(target_triangles=round(0.1 * len(triangles)), seed=0,
                                                        mode=mode)
    return vertices, triangles, result


def _error(vertices, triangles, result):
    return topstoc.hausdorff((vertices, triangles), (result.vertices, result.triangles), samples=100_000,
                             relative=True, percentile=0).symmetric


@pytest.mark.heavy
def test_a_result_above_1400_triangles_is_fitted_its_mean_lower_and_max_not_higher(data_dir):
    path = data_dir / "genus0/cgal_ChineseDragon-10kv.off"
    vertices, triangles, plain = _decimate(path, "quality")
    _, _, result = _decimate(path, "best")
    plain_error, error = _error(vertices, triangles, plain), _error(vertices, triangles, result)
    assert result.parameters["mode"] == "best" and plain.parameters["mode"] == "quality"
    assert len(result.triangles) == len(plain.triangles) > 1400
    assert result.stats.topology_kept
    assert invariants(len(result.vertices), result.triangles) == invariants(len(vertices), triangles)
    assert degenerate_or_duplicate(result.triangles) == (0, 0)
    out = np.asarray(result.vertices, dtype=float)
    t = np.asarray(result.triangles)
    area2 = np.linalg.norm(np.cross(out[t[:, 1]] - out[t[:, 0]], out[t[:, 2]] - out[t[:, 0]]), axis=1)
    assert (area2 > 0).all()
    # The fit lowers the dragon's mean by about 4 % (0.1020 -> 0.0979 % of the diagonal).
    assert error.mean < 0.98 * plain_error.mean
    assert error.max <= plain_error.max * (1 + 1e-4)


SCRIPT = """
import hashlib, sys
sys.path[:0] = sys.argv[1:3]
import numpy as np, topstoc
from topstoc.core import read_mesh
mesh = read_mesh(sys.argv[3])
v, t = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
r = topstoc.Mesh(v, t).decimate(target_triangles=round(0.1 * len(t)), seed=0, mode="best")
print(hashlib.sha256(np.asarray(r.vertices).tobytes() + np.asarray(r.triangles).tobytes()).hexdigest())
"""


@pytest.mark.heavy
def test_the_large_fit_is_the_same_on_any_thread_count(data_dir):
    outputs = outputs_by_thread_count(SCRIPT, data_dir / "genus0/cgal_ChineseDragon-10kv.off", counts=("1", "2"))
    assert len(set(outputs.values())) == 1, outputs


def test_a_best_result_is_made_again_from_its_samples_and_differs_from_quality(data_dir):
    path = data_dir / "genus0/cgal_ChineseDragon-10kv.off"
    _, _, plain = _decimate(path, "quality")
    vertices, triangles, best = _decimate(path, "best")
    assert not np.array_equal(best.vertices, plain.vertices)  # the fit moved vertices
    stats = best.stats
    replay = dict(placement="filtered", refine_vertices=stats.refine_vertices,
                  refine_triangles=stats.refine_triangles, refine_keeps_positions=stats.refine_keeps_positions)
    mesh = topstoc.Mesh(vertices, triangles)
    again = mesh.decimate_with_samples(best.samples, large_fit=True, **replay)
    assert np.array_equal(again.vertices, best.vertices) and np.array_equal(again.triangles, best.triangles)
    without = mesh.decimate_with_samples(plain.samples, **replay)
    assert np.array_equal(without.vertices, plain.vertices)


def test_the_command_line_and_the_batch_take_mode_best(data_dir, tmp_path):
    import json

    from topstoc.core.cli import main

    source = data_dir / "genus0/cgal_ChineseDragon-10kv.off"
    for mode in ("quality", "best"):
        assert main(["decimate", str(source), str(tmp_path / f"{mode}.obj"), "--triangles", "2000",
                     "--mode", mode]) == 0
    quality, best = (read_mesh(tmp_path / f"{mode}.obj") for mode in ("quality", "best"))
    assert len(best.triangles) == len(quality.triangles) and not np.array_equal(best.vertices, quality.vertices)
    out = tmp_path / "lods"
    assert main(["batch", "--input", str(source), "--output", str(out), "--ratio", "0.2", "--mode", "best",
                 "--workers", "0"]) == 0
    report = json.loads((out / "topstoc-report.json").read_text())
    assert report["settings"]["options"]["mode"] == "best" and not report["failures"]
