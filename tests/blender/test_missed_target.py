"""A missed target in the add-on (issue 37): Guided Decimate's status line, its redo panel, the
result object the panel reads, and the Blender batch's report. Loose triangles cannot go below
three vertices each, so a 10 % target is missed by a count computed here from the input."""

import json

import bpy
import numpy as np
import pytest

import reference
from conftest import DATA, PACKAGE
from helpers import make_object, select_only
from launch import background

LOOSE = 400
DETAIL = (f"{LOOSE:,} of the result's {LOOSE:,} triangles are loose pieces, each kept whole; "
          "weld the mesh first (Blender: Merge by Distance)")


def loose_triangles(name="Loose"):
    side = int(np.ceil(np.sqrt(LOOSE)))
    corners = np.array([[0.0, 0.0, 0.0], [0.4, 0.0, 0.0], [0.0, 0.4, 0.1]])
    vertices = np.concatenate([corners + [i % side, i // side, 0.0] for i in range(LOOSE)])
    return make_object(name, vertices, [(3 * i, 3 * i + 1, 3 * i + 2) for i in range(LOOSE)])


def expected_text():
    asked, got = round(0.1 * 3 * LOOSE), 3 * LOOSE
    return (f"target missed: {got:,} vertices for {asked:,} ({got - asked:,} over, "
            f"{100 * (got - asked) / asked:+.1f} %; topology: {DETAIL})")


def test_guided_decimate_reports_the_missed_target(ts, scene):
    loose_triangles()
    assert bpy.ops.topstoc.guided_decimate(ratio=0.1, quality="QUALITY") == {"FINISHED"}
    out = bpy.context.active_object
    assert len(out.data.vertices) == 3 * LOOSE
    assert out["topstoc_target_missed"] == expected_text()
    assert out["topstoc_over_budget"] == 3 * LOOSE - round(0.1 * 3 * LOOSE)
    assert out["topstoc_over_budget_reason"] == "topology"


def test_a_thin_curved_tube_reports_folds(ts, scene):
    """A tube wound as a helix with 4 rings a turn (shape_families.long_cable): at 1 % every
    collapse left would flip or fold a triangle, which the object's report says (not the
    topology: the tube is an annulus, counted by tests/reference.py)."""
    import shape_families

    vertices, faces = shape_families.long_cable(10000)
    assert reference.invariants(len(vertices), faces) == [(0, 2, True, True)]
    make_object("Cable", vertices, faces)
    assert bpy.ops.topstoc.guided_decimate(ratio=0.01, quality="FAST") == {"FINISHED"}
    out = bpy.context.active_object
    assert len(out.data.vertices) >= 10 * round(0.01 * len(vertices))
    assert out["topstoc_over_budget_reason"] == "folds"
    assert "folds: the collapses left would flip, fold or thin triangles" in out["topstoc_target_missed"]


class Layout:
    """Records what a draw function puts in a layout (labels and their icons)."""

    def __init__(self):
        self.labels = []

    def prop(self, *args, **kwargs):
        pass

    def row(self, **kwargs):
        return self

    column = row

    def label(self, text="", icon="NONE"):
        self.labels.append((text, icon))


class Redo:
    """The Guided Decimate operator's properties (the scene's settings, then ``values``), its
    reports and its layout: what execute and draw see in the redo panel."""

    def __init__(self, settings, **values):
        for name in settings.bl_rna.properties.keys():
            if name != "rna_type":
                setattr(self, name, getattr(settings, name))
        self.__dict__.update(values, output="NEW_OBJECT", target_missed="", reports=[], layout=Layout())
        self.properties = type("Set", (), {"is_property_set": staticmethod(lambda name: False)})()

    def report(self, kind, text):
        self.reports.append((kind, text))


def test_status_line_and_redo_panel_text(ts, scene, capfd):
    obj = loose_triangles()
    run = ts.blender.decimation.pipeline.decimate(bpy.context, obj, scene.topstoc, target={"ratio": 0.1})
    assert ts.blender.decimation.pipeline.summary(run).endswith("; " + expected_text())
    select_only(obj)
    capfd.readouterr()
    assert bpy.ops.topstoc.guided_decimate(ratio=0.1) == {"FINISHED"}
    reports = capfd.readouterr().out  # the operator's reports (the status bar), printed in background mode
    assert f"Warning: TopStoc: Loose: {expected_text()}" in reports
    assert f"; {expected_text()}; " in reports  # and in the Info line
    # The redo panel: execute keeps what was missed in the operator's target_missed, draw shows it
    # (background Blender keeps no operator instance, so both run on a stand-in with its properties).
    operator = bpy.types.TOPSTOC_OT_guided_decimate
    redo = Redo(scene.topstoc, ratio=0.1)
    select_only(obj)
    assert operator.execute(redo, bpy.context) == {"FINISHED"}
    assert redo.target_missed == f"Loose: {expected_text()}"
    assert ({"WARNING"}, f"TopStoc: Loose: {expected_text()}") in redo.reports
    operator.draw(redo, bpy.context)
    assert (f"Loose: {expected_text()}", "ERROR") in redo.layout.labels
    redo = Redo(scene.topstoc, ratio=1.0)
    select_only(obj)
    assert operator.execute(redo, bpy.context) == {"FINISHED"}
    assert redo.target_missed == "" and not any("target missed" in text for _, text in redo.reports)


def test_lod_chain_reports_the_lod_that_missed(ts, scene, capfd):
    loose_triangles()
    capfd.readouterr()
    assert bpy.ops.topstoc.lod_chain(ratios="1.0, 0.1") == {"FINISHED"}
    reports = capfd.readouterr().out
    assert f"Warning: TopStoc: Loose_LOD1: {expected_text()}" in reports and "Loose_LOD0: target" not in reports
    assert bpy.data.objects["Loose_LOD0"]["topstoc_target_missed"] == ""
    assert bpy.data.objects["Loose_LOD1"]["topstoc_target_missed"] == expected_text()


def test_symmetry_over_the_target_is_reported(ts, scene):
    """Suzanne mirrored at 5 %: the mirrored samples outgrow the plain draw's target."""
    bpy.ops.wm.obj_import(filepath=str(DATA / "open_boundary/kivy_suzanne_monkey.obj"))
    obj = bpy.context.selected_objects[0]
    co = np.array([v.co for v in obj.data.vertices])
    co[:, 0] -= 0.5 * (co[:, 0].min() + co[:, 0].max())  # mirror plane onto x = 0
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    select_only(obj)
    assert bpy.ops.topstoc.guided_decimate(ratio=0.05, use_symmetry=True, symmetry_axis="X") == {"FINISHED"}
    out = bpy.context.active_object
    asked, got = round(0.05 * len(obj.data.vertices)), len(out.data.vertices)
    assert got > 1.01 * asked
    assert out["topstoc_target_missed"].startswith(f"target missed: {got:,} vertices for {asked:,} ({got - asked:,} over")
    assert out["topstoc_target_missed"].endswith("; symmetry)") and out["topstoc_over_budget_reason"] == "symmetry"


MAKE_SCENE = """
import sys, bpy
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
side, v, f = 20, [], []
for i in range({count}):
    x, y = i % side, i // side
    v += [(x, y, 0.0), (x + 0.4, y, 0.0), (x, y + 0.4, 0.1)]
    f.append((3 * i, 3 * i + 1, 3 * i + 2))
mesh = bpy.data.meshes.new("Loose")
mesh.from_pydata(v, [], f)
bpy.context.scene.collection.objects.link(bpy.data.objects.new("Loose", mesh))
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""


def test_blender_batch_reports_the_missed_target(ts, scene, tmp_path):
    path = tmp_path / "loose.blend"
    done = background(expr=MAKE_SCENE.format(count=LOOSE, path=str(path)), timeout=120)
    assert done.returncode == 0 and path.exists(), done.stdout[-2000:] + done.stderr[-2000:]
    report = tmp_path / "report.json"
    done = background(PACKAGE / "batch.py", "--input", path, "--ratio", "0.1", "--output", tmp_path / "out",
                      "--json", report, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Loose " + expected_text() in done.stdout
    entry = json.loads(report.read_text())["results"][0]
    asked, got = round(0.1 * 3 * LOOSE), 3 * LOOSE
    missed = [lod["target_missed"] for o in entry["objects"] for lod in o["lods"]]
    assert missed == [{"asked": asked, "got": got, "unit": "vertices", "off": got - asked,
                       "fraction": pytest.approx((got - asked) / asked), "reason": "topology", "detail": DETAIL}]


def test_guided_decimate_warns_when_the_topology_is_not_kept(ts, scene, capfd, monkeypatch):
    """A book of three pages and four spheres, whose results are made to say 2 components were
    lost (tests/broken_engine.py: the engine itself keeps them): Guided Decimate warns; with the
    real engine it keeps the five pieces (counted here from the result object) and says nothing."""
    import importlib

    import meshgen
    from broken_engine import reporting_lost_components
    engine = importlib.import_module(ts.__name__ + ".core.support.native").engine
    vertices, triangles = meshgen.disjoint(meshgen.subdivide(*meshgen.book(3), 3), *[meshgen.icosphere(1)] * 4)
    obj = make_object("Book", vertices, triangles)
    reporting_lost_components(monkeypatch, engine)
    capfd.readouterr()
    assert bpy.ops.topstoc.guided_decimate(ratio=0.1, quality="FAST", seed=1) == {"FINISHED"}
    reports = capfd.readouterr().out
    assert "Warning: TopStoc: Book: topology NOT kept: " in reports and ", 2 lost components" in reports
    monkeypatch.undo()
    for quality in ("FAST", "QUALITY"):
        select_only(obj)
        assert bpy.ops.topstoc.guided_decimate(ratio=0.1, quality=quality, seed=1) == {"FINISHED"}
        assert "topology NOT kept" not in capfd.readouterr().out
        mesh = bpy.context.active_object.data
        triangles = [polygon.vertices[:] for polygon in mesh.polygons]
        assert reference.components(len(mesh.vertices), triangles).max() + 1 == 5  # the input's

