"""File › Import › OFF: the add-on's operator gives the positions and polygons the file holds
(checked against tests/reference.py's independent reader), n-gons kept whole."""

import bpy
import numpy as np
import pytest

import reference
from conftest import DATA
from helpers import positions


def test_menu_entry_is_registered(ts):
    entries = [getattr(f, "__name__", "") for f in bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()]
    assert "menu_entry" in entries


@pytest.mark.parametrize("name", ["genus0/cgal_fandisk.off", "open_boundary/cgal_mushroom.off"])
def test_off_file_imports_like_the_reference_reader(ts, scene, name):
    path = DATA / name
    vertices, triangles = reference.read_off(path)
    assert bpy.ops.topstoc.import_off(filepath=str(path)) == {"FINISHED"}
    obj = bpy.context.active_object
    np.testing.assert_allclose(positions(obj.data), vertices, rtol=1e-6, atol=1e-6)
    obj.data.calc_loop_triangles()
    tris = np.array([tuple(t.vertices) for t in obj.data.loop_triangles])
    assert sorted(map(tuple, np.sort(tris, axis=1).tolist())) == sorted(map(tuple, np.sort(triangles, axis=1).tolist()))


def test_polygons_stay_whole(ts, scene, tmp_path):
    path = tmp_path / "mixed.off"
    path.write_text("OFF\n6 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n2 1 0\n"
                    "4 0 1 2 3\n4 1 4 5 2\n3 0 3 2\n")
    assert bpy.ops.topstoc.import_off(filepath=str(path)) == {"FINISHED"}
    mesh = bpy.context.active_object.data
    assert [tuple(p.vertices) for p in mesh.polygons] == [(0, 1, 2, 3), (1, 4, 5, 2), (0, 3, 2)]
    assert bpy.context.active_object.name == "mixed"


def test_a_broken_file_is_reported(ts, scene, tmp_path):
    path = tmp_path / "broken.off"
    path.write_text("OFF\n3 1 0\n0 0 0\n")
    with pytest.raises(RuntimeError, match="broken.off"):
        bpy.ops.topstoc.import_off(filepath=str(path))
    assert len(bpy.data.objects) == 0


def test_skipped_faces_are_reported_as_a_warning(ts, scene, tmp_path, capfd):
    # A 2-corner face reads as no polygon; the reader's MeshFileWarning reaches the operator's report.
    path = tmp_path / "lines.off"
    path.write_text("OFF\n4 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n2 2 3\n3 0 2 3\n")
    capfd.readouterr()
    assert bpy.ops.topstoc.import_off(filepath=str(path)) == {"FINISHED"}
    mesh = bpy.context.active_object.data
    assert [tuple(p.vertices) for p in mesh.polygons] == [(0, 1, 2), (0, 2, 3)]
    out, err = capfd.readouterr()
    assert "lines.off: skipped 1 face with fewer than 3 corners (the first at line 8)" in out + err


def test_an_empty_file_is_refused_by_name(ts, scene, tmp_path):
    path = tmp_path / "empty.off"
    path.write_text("OFF\n0 0 0\n")
    with pytest.raises(RuntimeError, match="empty.off: the mesh has no triangles"):
        bpy.ops.topstoc.import_off(filepath=str(path))
    assert len(bpy.data.objects) == 0


def test_nothing_is_selected_after_import(ts, scene):
    """As Blender's own importers: an invisible selection would be what Edit Mode's tools act on."""
    assert bpy.ops.topstoc.import_off(filepath=str(DATA / "genus0" / "cgal_fandisk.off")) == {"FINISHED"}
    mesh = bpy.context.active_object.data
    for items in (mesh.vertices, mesh.edges, mesh.polygons):
        flags = np.ones(len(items), dtype=bool)
        items.foreach_get("select", flags)
        assert len(items) > 0 and not flags.any()
