"""Hausdorff error colours, legend, colour attribute, samples and clusters, turntable: real
Blender 3.4 GUI under Xvfb, screenshots checked pixel by pixel (one launch)."""

import sys

import numpy as np
import pytest

from conftest import BUILD, DATA
from pixels import count_near, count_on_ramp, crop, outside

sys.path.insert(0, str(BUILD / "python"))
from topstoc.core.support import colors  # noqa: E402  (bpy-free)


def ramp():
    return colors.error_colors(np.linspace(0, 1, 64), 1.0)


@pytest.fixture(scope="module")
def report(gui, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("metrics_gui")
    scene = gui.scene(tmp / "dragon.blend", "--mesh", DATA / "genus0" / "cgal_ChineseDragon-10kv.off",
                      "--name", "Dragon", "--transform", "--decimate", 0.03, "--measure")
    return gui.run("metrics_script.py", scene, tmp / "out")


def image(report, name):
    return np.load(report["shots"][name].replace(".png", ".npy"))


def test_gui_checks_pass(report):
    assert report["checks"] and all(report["checks"].values()), report["checks"]


def test_error_colours_appear_on_the_object_and_go_when_toggled(report):
    on, off, again = (image(report, n) for n in ("error_on", "error_off", "error_toggled_off"))
    rect = report["regions"]["error_on"]["Dragon_TopStoc"]
    coloured = count_on_ramp(crop(on, rect), ramp())
    area = crop(on, rect).shape[0] * crop(on, rect).shape[1]
    assert coloured > 0.1 * area, (coloured, area)
    assert count_on_ramp(crop(off, rect), ramp()) < 0.002 * area
    assert count_on_ramp(crop(again, rect), ramp()) < 0.002 * area
    # transforms: the colours lie on the object, not elsewhere in the view
    view = report["regions"]["error_on"]["view"]
    legend = [view[0], view[1], view[0] + 260, view[1] + 260]
    stray = count_on_ramp(outside(on, rect, [legend[2], view[1], view[2], view[3]]), ramp())
    assert stray < 0.01 * coloured, stray
    assert report["values"]["drawn_error"] and report["values"]["drawn_error"][0][0] == "error"


def test_legend_shows_with_the_error_colours(report):
    on, off = image(report, "error_on"), image(report, "error_off")
    x0, y0 = report["regions"]["error_on"]["view"][:2]
    legend = [x0 + 15, y0 + 45, x0 + 45, y0 + 215]  # the colour bar (overlays.LEGEND_*)
    assert count_on_ramp(crop(on, legend), ramp()) > 0.8 * 18 * 170
    assert count_on_ramp(crop(off, legend), ramp()) == 0
    assert report["values"]["legend_object"] == "Dragon_TopStoc"


def test_colour_attribute_shows_errors_without_the_overlay(report):
    if report["values"].get("capture") == "view framebuffer":
        pytest.skip("Blender 4.x capture (the 3D view's framebuffer read in a draw handler) holds the "
                    "overlays but not the solid-mode shading of meshes; checked in Blender 3.4")
    shot = image(report, "error_attribute")
    rect = report["regions"]["error_attribute"]["Dragon_TopStoc"]
    # Solid mode shades the attribute colours, so compare hue classes rather than exact colours:
    pixels = crop(shot, rect).reshape(-1, 3)
    saturated = pixels[(pixels.max(axis=1) - pixels.min(axis=1)) > 0.25]
    assert len(saturated) > 0.05 * len(pixels)


def test_clusters_and_samples_on_the_original(report):
    on, off, samples = (image(report, n) for n in ("clusters_on", "clusters_off", "samples_only"))
    rect = report["regions"]["clusters_on"]["Dragon"]
    red_on = count_near(crop(on, rect), colors.CLUSTER_CORNER)
    assert red_on > 100 and count_near(crop(off, rect), colors.CLUSTER_CORNER) < 5
    blue = count_near(crop(samples, rect), colors.SAMPLE)
    assert blue > 100 and count_near(crop(off, rect), colors.SAMPLE) < 5
    names = {name for name, _kind, _count in report["values"]["drawn_clusters"]}
    assert names == {"clusters", "samples"}
