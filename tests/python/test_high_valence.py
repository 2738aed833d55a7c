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
from fan_meshes import cone, cylinder_caps, fan_disc, uv_sphere  # noqa: E402


@pytest.mark.parametrize("mode", ["quality", "fast"])
# The double cone in fast mode: at 4,000 the draw for the target stalls, at 1,000 a lower draw
# of the budget passes does; the final check rejected both, and both came back broken.
@pytest.mark.parametrize("shape, size", [(cone, 1000), (cone, 4000), (fan_disc, 3000), (cylinder_caps, 1000)])
def test_fans_keep_topology(shape, size, mode):
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


def test_fast_capped_cylinder_past_the_repair_rounds():
    # 7,000 segments at 10 %: each repair round splits one cluster per cap and the 200 rounds run
    # out before the caps' fans are clean; the result must still keep the topology (a closed
    # tube: one sphere).
    vertices, triangles = cylinder_caps(7000)
    result = topstoc.decimate(topstoc.Mesh(vertices, triangles), ratio=0.1, mode="fast", seed=0)
    out = np.asarray(result.triangles)
    assert reference.invariants(len(result.vertices), out) == reference.invariants(len(vertices), triangles)
    assert reference.degenerate_or_duplicate(out) == (0, 0)
    assert len(result.vertices) <= 0.1 * len(vertices) + 1
    assert np.array_equal(result.vertices, vertices[result.kept])  # fast mode keeps input positions


def test_fast_cone_draft_is_the_full_result():
    # At 1,000 the draw for the target is clean and a lower draw stalls: the draft (the Live
    # Preview) must not show that lower draw's broken surface.
    vertices, triangles = cone(1000)
    mesh = topstoc.Mesh(vertices, triangles)
    draft = topstoc.decimate(mesh, ratio=0.25, mode="fast", seed=0, draft=True)
    full = topstoc.decimate(mesh, ratio=0.25, mode="fast", seed=0)
    assert reference.invariants(len(draft.vertices), np.asarray(draft.triangles)) == \
        reference.invariants(len(vertices), triangles)
    assert np.array_equal(draft.kept, full.kept) and np.array_equal(draft.triangles, full.triangles)


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_cone_refined_from_a_smaller_first_pass(mode):
    # refine=4: the collapses start from a first pass of four times the target, not the whole
    # mesh (as quality mode does on meshes past 8 x QUALITY_COLLAPSES vertices: the double cone of
    # n = 80,000). That pass stalls on the cone and was collapsed broken.
    vertices, triangles = cone(4000)
    result = topstoc.decimate(topstoc.Mesh(vertices, triangles), ratio=0.1, mode=mode, seed=0, refine=4)
    out = np.asarray(result.triangles)
    assert result.stats.topology_kept
    assert reference.invariants(len(result.vertices), out) == reference.invariants(len(vertices), triangles)
    assert reference.degenerate_or_duplicate(out) == (0, 0)
    assert len(result.vertices) <= 0.1 * len(vertices) + 1


def sphere_deviation(result):
    """Max radial deviation from the unit sphere of points spread over every output triangle."""
    corners = np.asarray(result.vertices)[np.asarray(result.triangles)]
    weights = np.array([(a, b, 1 - a - b) for a in np.linspace(0, 1, 7) for b in np.linspace(0, 1, 7) if a + b <= 1])
    points = np.einsum("sk,fkd->fsd", weights, corners).reshape(-1, 3)
    return np.abs(1 - np.linalg.norm(points, axis=1)).max()


# Every triangle of a UV sphere of 1,000 or 2,000 segments (50 rings) is a sliver. Quality mode
# took the input's slivers first, by shape, before the collapses by error: that ate the poles'
# first rings (the pole fanned out to 0.34 of the radius, 0.016 off the sphere at 1,000
# segments). Above 80,000 vertices its stochastic first pass, clustered by hop count, ran its
# triangles across many rings (0.062 off at 2,000 segments; with the top cap flipped, as this
# helper once made it, the first pass missed the 10 % target: 2,104 vertices for 9,800). Ideal:
# about 0.0004 at 10 %. Fast mode, the stochastic pass alone, was 0.06-0.07 off at 10 % and 0.21
# at 2 %; on a sliver-heavy mesh it now collapses the whole mesh keeping input positions.
@pytest.mark.parametrize("mode", ["quality", "fast"])
@pytest.mark.parametrize("segments, ratio, bound", [(1000, 0.1, 0.002), (2000, 0.1, 0.002), (2000, 0.02, 0.006)])
def test_uv_sphere_of_slivers_keeps_to_the_sphere(segments, ratio, bound, mode):
    vertices, triangles = uv_sphere(segments)
    result = topstoc.decimate(topstoc.Mesh(vertices, triangles), ratio=ratio, mode=mode, seed=0)
    assert len(result.vertices) == round(ratio * len(vertices))
    assert sphere_deviation(result) < bound


@pytest.mark.parametrize("size", [300, 2000])
def test_fanned_disc_rim_is_thinned_evenly(size):
    # The sliver clean-up before quality mode's collapses took the fan's slivers in triangle
    # order: each collapse of a rim edge left the next sliver as thin, so it swept one arc of the
    # rim into a single triangle (a gap of 1.8 radians at 10 % of 2,000, max error 9.7 % of the
    # diagonal). Measured against the circle: the widest gap between consecutive rim vertices.
    vertices, triangles = fan_disc(size)
    result = topstoc.decimate(topstoc.Mesh(vertices, triangles), ratio=0.1, mode="quality", seed=0)
    out = np.asarray(result.vertices)
    radius = np.linalg.norm(out[:, :2], axis=1)
    assert np.all(np.abs(radius[radius > 0.5] - 1) < 0.01) and np.all(out[:, 2] == 0)  # the fit may move the rim
    angles = np.sort(np.arctan2(out[radius > 0.5, 1], out[radius > 0.5, 0]))
    gaps = np.diff(np.r_[angles, angles[0] + 2 * np.pi])
    assert len(angles) >= 0.1 * size - 1
    assert gaps.max() < 4 * 2 * np.pi / len(angles)  # evenly: at most 4 times the mean gap
