"""Auto Regenerate in a real Blender GUI under Xvfb (one launch): the source edited in Edit Mode
(several moves in quick succession) regenerates its result once, after the debounce and only
once the artist is back in Object Mode; the result shows the edit and keeps its own transform
and material."""

import pytest

from conftest import DATA


@pytest.fixture(scope="module")
def report(gui, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("regenerate_gui")
    scene = gui.scene(tmp / "suzanne.blend", "--mesh", DATA / "open_boundary" / "kivy_suzanne_monkey.obj",
                      "--name", "Suzanne")
    return gui.run("regenerate_script.py", scene, tmp / "out")


def test_gui_checks_pass(report):
    assert report["checks"] and all(report["checks"].values()), report["checks"]


def test_regenerated_once_after_the_debounce(report):
    assert report["values"]["regenerations"] == 1
    assert report["values"]["seconds_after_edit"] >= 0.75
