"""Topology overlays in a real Blender 3.4 GUI under Xvfb (one launch): handle loops yellow,
tunnel loops turquoise, generator edges pink, boundary vertices red, the active loop thicker,
depth-tested, following the object's transform, each with a toggle, gone when the add-on is
disabled; editing and undo from the panel; the background search's Esc."""

import sys

import numpy as np
import pytest

from conftest import BUILD, DATA
from pixels import count_near, crop, outside

sys.path.insert(0, str(BUILD / "python"))
from topstoc.core.support import colors  # noqa: E402  (bpy-free)

OVERLAYS = {"handles": colors.HANDLE, "tunnels": colors.TUNNEL, "generators": colors.GENERATOR,
            "boundary": colors.BOUNDARY}


@pytest.fixture(scope="module")
def report(gui, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("topology_gui")
    scene = gui.scene(tmp / "turbine.blend", "--mesh", DATA / "genus_positive" / "cgal_turbine.off",
                      "--name", "Shape", "--subdivide", 1, "--transform", "--loops")
    return gui.run("topology_script.py", scene, tmp / "out")


def image(report, name):
    return np.load(report["shots"][name].replace(".png", ".npy"))


def region(report, shot, name="Shape"):
    return report["regions"][shot][name]


def test_gui_checks_pass(report):
    assert report["checks"] and all(report["checks"].values()), report["checks"]
    assert report["values"]["genus"] == 11 and report["values"]["genus_after_cut"] == 10


@pytest.mark.parametrize("shot, colour", [("handles_active", "handles"), ("tunnels", "tunnels"),
                                          ("generators", "generators"), ("boundary", "boundary")])
def test_each_overlay_shows_its_colour_on_the_object_only(report, shot, colour):
    on, off = image(report, shot), image(report, "topology_off")
    rect = region(report, shot)
    shown = count_near(crop(on, rect), OVERLAYS[colour])
    assert shown > 40, shown
    assert count_near(crop(off, rect), OVERLAYS[colour]) <= 2          # absent with the toggle off
    view = report["regions"][shot]["view"]
    assert count_near(outside(on, rect, view), OVERLAYS[colour]) <= 0.02 * shown  # transform applied
    for other, rgba in OVERLAYS.items():                                # the other toggles are off
        if other != colour and not (colour == "boundary" and other == "handles"):
            assert count_near(crop(on, rect), rgba) <= max(3, 0.05 * shown), other


def test_active_loop_is_thicker(report):
    thin, active = image(report, "handles_thin"), image(report, "handles_active")
    rect = region(report, "handles_active")
    assert count_near(crop(active, rect), colors.HANDLE) > 1.1 * count_near(crop(thin, rect), colors.HANDLE)


def test_all_overlays_together(report):
    shot = image(report, "topology_all")
    rect = region(report, "topology_all")
    for name in ("handles", "tunnels", "generators"):
        assert count_near(crop(shot, rect), OVERLAYS[name]) > 20, name


def test_overlays_are_depth_tested(report):
    shot = image(report, "occluded")
    obj, plane = region(report, "occluded"), region(report, "occluded", "Occluder")
    hidden = [max(obj[0], plane[0]), max(obj[1], plane[1]), min(obj[2], plane[2]), min(obj[3], plane[3])]
    assert hidden[2] - hidden[0] > 30 and hidden[3] - hidden[1] > 30, (obj, plane)
    visible = sum(count_near(outside(shot, hidden, obj), OVERLAYS[n]) for n in ("handles", "tunnels", "generators"))
    behind = sum(count_near(crop(shot, hidden), OVERLAYS[n]) for n in ("handles", "tunnels", "generators"))
    assert visible > 50 and behind <= 2, (visible, behind)


def test_nothing_drawn_after_the_addon_is_disabled(report):
    shot = image(report, "disabled")
    rect = region(report, "disabled")
    before = image(report, "after_search")
    assert count_near(crop(before, rect), colors.HANDLE) > 40
    assert all(count_near(crop(shot, rect), rgba) <= 2 for rgba in OVERLAYS.values())


def test_search_cancel_and_finish(report):
    state, message = report["values"]["cancel_state"]
    assert message == "Search cancelled"
    assert "11 handle and 11 tunnel loops" in report["values"]["search_message"]
