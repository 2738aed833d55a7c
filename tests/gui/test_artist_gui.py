"""The artist's panel in a real Blender GUI under Xvfb (one launch): the decimation panel at
the default sidebar width with no red "invalid" field and labels that fit, the Live Preview's
wireframe (more edge pixels with it than without), and the Topology panel's help."""

import numpy as np
import pytest

from conftest import DATA
from pixels import crop


@pytest.fixture(scope="module")
def report(gui, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("artist_gui")
    scene = gui.scene(tmp / "suzanne.blend", "--mesh", DATA / "open_boundary" / "kivy_suzanne_monkey.obj",
                      "--name", "Suzanne", "--subdivide", 1)
    return gui.run("artist_script.py", scene, tmp / "out")


def image(report, name):
    return np.load(report["shots"][name].replace(".png", ".npy"))


def test_gui_checks_pass(report):
    assert report["checks"] and all(report["checks"].values()), report["checks"]


def test_no_red_field_in_the_panel(report):
    """Blender draws an invalid search field in red (about (0.6, 0.15, 0.15))."""
    pixels = crop(image(report, "artist_panel"), report["regions"]["sidebar"])
    red = (pixels[..., 0] > 0.4) & (pixels[..., 1] < 0.25) & (pixels[..., 2] < 0.25)
    assert red.sum() <= 5, red.sum()


def test_preview_wireframe_draws_edges(report):
    if report["values"].get("capture") == "view framebuffer":
        pytest.skip("Blender 4.x capture (the 3D view's framebuffer read in a draw handler) holds the "
                    "overlays but not the solid-mode shading the wire is told apart from; checked in Blender 3.4")
    rect = report["regions"]["preview_wire"]["Suzanne_TopStocPreview"]
    wire = crop(image(report, "preview_wire"), rect)
    plain = crop(image(report, "preview_nowire"), rect)

    def dark(pixels):
        return int((pixels.max(axis=-1) < 0.12).sum())

    assert dark(wire) > 1.5 * dark(plain) + 200, (dark(wire), dark(plain))


def test_topology_help_is_plain(report):
    assert "handles" in report["values"]["genus_tooltip"].lower()
