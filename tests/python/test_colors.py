"""Overlay and error colours (topstoc.core.support.colors): the ramp, the legend, cluster classes."""

import numpy as np
import pytest

from topstoc.core.support import colors


def test_error_ramp_ends_and_clamps():
    out = colors.error_colors([0.0, 2.0, 4.0, 9.0, -1.0], scale=4.0)
    assert out.dtype == np.float32 and out.shape == (5, 4)
    np.testing.assert_allclose(out[0, :3], colors.ERROR_RAMP[0][1], atol=1e-6)     # 0 -> blue
    np.testing.assert_allclose(out[1, :3], colors.ERROR_RAMP[2][1], atol=1e-6)     # half -> green stop
    np.testing.assert_allclose(out[2, :3], colors.ERROR_RAMP[-1][1], atol=1e-6)    # scale -> red
    np.testing.assert_allclose(out[3], out[2])                                      # above the scale: red
    np.testing.assert_allclose(out[4], out[0])                                      # negative: blue
    assert np.all(out[:, 3] == 1.0)


def test_error_ramp_interpolates_between_stops():
    (s0, c0), (s1, c1) = colors.ERROR_RAMP[0], colors.ERROR_RAMP[1]
    t = (s0 + s1) / 2
    np.testing.assert_allclose(colors.error_colors([t], 1.0)[0, :3], (np.array(c0) + c1) / 2, atol=1e-6)


def test_error_colours_of_missing_values_and_zero_scale():
    out = colors.error_colors([np.nan, 1.0], scale=0.0, alpha=0.5)
    np.testing.assert_allclose(out[0], (0.5, 0.5, 0.5, 0.5))
    np.testing.assert_allclose(out[1, :3], colors.ERROR_RAMP[0][1], atol=1e-6)


def test_legend_ticks_give_absolute_and_percent():
    ticks = colors.legend_ticks(0.5, 10.0, count=3)
    assert [t for t, _ in ticks] == [0.0, 0.5, 1.0]
    assert ticks[-1][1] == "0.5 (5 %)" and ticks[0][1] == "0 (0 %)"
    assert colors.legend_ticks(1.0, 0.0, count=2)[1][1] == "1"


def test_cluster_colours_are_pastel_distinct_and_grey_for_none():
    labels = np.arange(-1, 40)
    out = colors.cluster_colors(labels)
    np.testing.assert_allclose(out[0], (0.5, 0.5, 0.5, 1.0))
    rgb = out[1:, :3]
    assert np.all(rgb.max(axis=1) == pytest.approx(0.95, abs=1e-6))
    assert np.all(rgb.max(axis=1) - rgb.min(axis=1) <= 0.35 * 0.95 + 1e-6)  # pastel: low saturation
    # neighbouring ids differ clearly
    assert np.all(np.abs(np.diff(rgb, axis=0)).max(axis=1) > 0.05)
    # no cluster colour can be mistaken for the overlay colours
    for overlay in (colors.HANDLE, colors.TUNNEL, colors.GENERATOR, colors.BOUNDARY, colors.SAMPLE,
                    colors.CLUSTER_CORNER, colors.CLUSTER_BORDER):
        assert np.abs(rgb - np.array(overlay[:3])).max(axis=1).min() > 0.12


def test_cluster_face_classes_match_a_brute_force_count():
    rng = np.random.default_rng(3)
    labels = rng.integers(0, 4, size=30)
    triangles = rng.integers(0, 30, size=(200, 3))
    out = colors.cluster_face_colors(triangles, labels)
    for face, colour in zip(triangles, out):
        distinct = len({labels[v] for v in face})
        if distinct == 3:
            assert tuple(colour) == pytest.approx(colors.CLUSTER_CORNER)
        elif distinct == 2:
            assert tuple(colour) == pytest.approx(colors.CLUSTER_BORDER)
        else:
            assert tuple(colour) == pytest.approx(tuple(colors.cluster_colors([labels[face[0]]])[0]))
