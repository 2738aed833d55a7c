"""Quality results above 1,400 triangles are fitted to the input in one least-squares round
(native/src/decimate/tiny_fit.cpp, fit_large): its normal equations solved by conjugate
gradients, the move kept only where threshold walks find the surfaces no farther apart than
the max before it.

Errors by topstoc.hausdorff (checked against CGAL in test_hausdorff_peers.py). The figures
compared with are main's before the fit reached these sizes (commit 4e8fb2f, same seed and
samples): the mean must fall by a margin, the max must not grow.
"""

import numpy as np


import topstoc
from topstoc.core import read_mesh
from reference import invariants

# cgal_ChineseDragon-10kv.off at 10 %: 1,998 triangles; before this fit a mean of 0.10199 %
# and a max of 0.77672 % of the diagonal (the fit: 0.09800 %, the same max).
MAIN_MEAN, MAIN_MAX = 0.101991e-2, 0.776720e-2


def test_a_result_above_1400_triangles_is_fitted_its_mean_lower_and_max_not_higher(data_dir):
    mesh = read_mesh(data_dir / "genus0/cgal_ChineseDragon-10kv.off")
    vertices, triangles = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    result = topstoc.Mesh(vertices, triangles).decimate(target_triangles=round(0.1 * len(triangles)), seed=0)
    assert len(result.triangles) > 1400
    assert result.stats.topology_kept
    assert invariants(len(result.vertices), result.triangles) == invariants(len(vertices), triangles)
    out = np.asarray(result.vertices, dtype=float)
    t = np.asarray(result.triangles)
    area2 = np.linalg.norm(np.cross(out[t[:, 1]] - out[t[:, 0]], out[t[:, 2]] - out[t[:, 0]]), axis=1)
    assert (area2 > 0).all()
    error = topstoc.hausdorff((vertices, triangles), (result.vertices, result.triangles), samples=100_000,
                              relative=True, percentile=0)
    assert error.symmetric.mean < 0.98 * MAIN_MEAN
    assert error.symmetric.max <= MAIN_MAX * (1 + 1e-4)

