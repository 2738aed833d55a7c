"""Every text of the TopStoc panels whole at Blender's default sidebar width (one launch): each
panel open, in Object Mode (options off, then every option that shows more settings on) and
Edit Mode, its layout as Blender resolved it measured against the
width Blender's layout rules give each button (label_widths.py). Then Frame Loop on the shortest
handle or tunnel loop, from a view that shows the whole object small."""

import pytest

from conftest import DATA


@pytest.fixture(scope="module")
def report(gui, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("labels_gui")
    scene = gui.scene(tmp / "torus.blend", "--mesh", DATA / "genus_positive" / "cgal_double-torus-example.off",
                      "--name", "Shape", "--decimate", 0.2, "--measure", "--loops")
    return gui.run("labels_script.py", scene, tmp / "out", screen="1280x2400")


def test_every_panel_was_measured(report):
    texts = report["values"]["texts"]
    assert texts["object"] > 100 and texts["edit"] > 100 and texts["options"] > texts["object"] + 5, texts
    # Blender's default sidebar, less its tab column and the panel margins
    assert 150 < report["values"]["content_width"] < 260, report["values"]


def test_gui_checks_pass(report):
    assert report["checks"] and all(report["checks"].values()), (report["checks"], report["values"].get("loop_extent"))


def test_no_text_is_cut(report):
    cut = ["{}: {} '{}' needs {} px of {}".format(*row[:5]) for row in report["values"]["cut"]]
    assert not cut, "\n".join(cut)
