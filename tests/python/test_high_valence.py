"""Fans of slivers around a vertex of very high valence (issue 39, "no slow corner"): a double
cone, a disc fanned from its centre and a cylinder with fanned caps, decimated in both modes,
keep each component's Euler characteristic, boundary loops, manifoldness and orientability as an
independent numpy count finds them (tests/reference.py), with no degenerate or repeated triangle.
Their speed is in tests/bench/bench_high_valence.py."""

import pathlib
import sys

import numpy as np
import pytest

import topstoc

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import reference  # noqa: E402
from fan_meshes import cone, cylinder_caps, fan_disc  # noqa: E402


# Fast mode on the double cone does not keep its topology, on main before this test too: the
# engine itself reports it (topology_kept False, bad_link issues remaining; at n = 20,000 and
# ratio 0.1 it also stops at 10,013 vertices for a target of 2,000). Strict: this fails once fixed.
FAST_CONE = pytest.mark.xfail(strict=True, reason="fast mode breaks the double cone's topology (reported by the engine)")


@pytest.mark.parametrize("mode", ["quality", "fast"])
@pytest.mark.parametrize("shape, size", [(cone, 4000), (fan_disc, 3000), (cylinder_caps, 1000)])
def test_fans_keep_topology(shape, size, mode, request):
    if shape is cone and mode == "fast":
        request.applymarker(FAST_CONE)
    vertices, triangles = shape(size)
    expected = reference.invariants(len(vertices), triangles)
    assert all(manifold and orientable for _, _, manifold, orientable in expected)  # the input is valid
    result = topstoc.decimate(topstoc.Mesh(vertices, triangles), ratio=0.25, mode=mode, seed=0)
    out = np.asarray(result.triangles)
    assert len(result.vertices) <= 0.3 * len(vertices)
    assert reference.invariants(len(result.vertices), out) == expected
    assert reference.degenerate_or_duplicate(out) == (0, 0)
    used = np.unique(out)
    assert len(used) == len(result.vertices)  # no vertex left without a triangle
    assert np.all(np.isfinite(result.vertices))
