"""File › Import › OFF (.off): Blender reads OBJ, PLY and STL itself; OFF goes through the
add-on's own reader (topstoc.core.api.io), which also takes .off.gz and per-vertex colours."""

from __future__ import annotations

import os
import warnings

import bpy
import numpy as np
from bpy.props import CollectionProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from ...core.api.io import MeshFileWarning, read_mesh
from ..io import mesh_access, mesh_write


def polygon_corners(triangles: np.ndarray, triangle_polygon: np.ndarray):
    """(corner vertex ids, corners per polygon) that undo the reader's fan triangulation: a
    polygon (v0, v1, ..., vk) was stored as triangles (v0, vi, vi+1)."""
    m = len(triangles)
    if m == 0:
        return np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.int32)
    new_polygon = np.r_[True, triangle_polygon[1:] != triangle_polygon[:-1]]
    last = np.r_[new_polygon[1:], True]
    slots = np.stack([new_polygon, np.ones(m, dtype=bool), last], axis=1)  # v0 once, vi each, vk at the end
    corners = triangles[slots]
    totals = np.diff(np.r_[np.flatnonzero(new_polygon), m]) + 2
    return corners.astype(np.int32), totals.astype(np.int32)


def read_with_warnings(path: str):
    """(MeshData, what the reader skipped: MeshFileWarning messages), for the operator's report."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshFileWarning)
        data = read_mesh(path)
    for w in caught:
        if not issubclass(w.category, MeshFileWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return data, [str(w.message) for w in caught if issubclass(w.category, MeshFileWarning)]


def mesh_from_file(path: str, name: str, notes: list) -> bpy.types.Mesh:
    """A Blender mesh of the file's polygons; the reader's warnings are appended to notes."""
    data, messages = read_with_warnings(path)
    notes.extend(m.replace(path, os.path.basename(path), 1) for m in messages)
    corners, totals = polygon_corners(data.triangles, data.triangle_polygon)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(data.num_vertices)
    mesh_write.write_positions(mesh, data.vertices)
    mesh.loops.add(len(corners))
    mesh_access.write_indices(mesh, ".corner_vert", mesh.loops, "vertex_index", corners)
    mesh.polygons.add(len(totals))
    mesh_write.write_polygon_loops(mesh, np.r_[0, np.cumsum(totals)[:-1]], totals)
    mesh.update(calc_edges=True)
    if data.vertex_colors is not None:
        colors = np.ones((data.num_vertices, 4), dtype=np.float32)
        colors[:, :data.vertex_colors.shape[1]] = data.vertex_colors
        layer = mesh.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
        layer.data.foreach_set("color", colors.ravel())
    mesh.validate()
    deselect_all(mesh)
    return mesh


#: Blender keeps the selection in these attributes; without them nothing is selected.
SELECTION_ATTRIBUTES = (".select_vert", ".select_edge", ".select_poly")


def deselect_all(mesh) -> None:
    """Nothing selected, as Blender's own importers leave a mesh: Edit Mode tools act on a selection.
    The attributes are removed rather than written (writing "select" crashed bpy 5.0.1)."""
    for name in SELECTION_ATTRIBUTES:
        layer = mesh.attributes.get(name)
        if layer is not None:
            mesh.attributes.remove(layer)


class TOPSTOC_OT_import_off(bpy.types.Operator, ImportHelper):
    """Import an OFF mesh (Object File Format; .off or .off.gz) through TopStoc's reader"""

    bl_idname = "topstoc.import_off"
    bl_label = "Import OFF"
    bl_options = {"REGISTER", "UNDO", "PRESET"}

    filename_ext = ".off"
    filter_glob: StringProperty(default="*.off;*.off.gz", options={"HIDDEN"})
    files: CollectionProperty(type=bpy.types.OperatorFileListElement, options={"HIDDEN", "SKIP_SAVE"})
    directory: StringProperty(subtype="DIR_PATH", options={"HIDDEN", "SKIP_SAVE"})

    def execute(self, context):
        paths = [os.path.join(self.directory, f.name) for f in self.files if f.name] or [self.filepath]
        objects, notes = [], []
        for path in paths:
            name = os.path.basename(path).split(".")[0] or "OFF"
            try:
                mesh = mesh_from_file(path, name, notes)
            except (OSError, ValueError) as error:
                self.report({"ERROR"}, f"{os.path.basename(path)}: {error}")
                continue
            obj = bpy.data.objects.new(name, mesh)
            context.collection.objects.link(obj)
            objects.append(obj)
        for note in notes:  # what the reader skipped, e.g. faces with fewer than 3 corners
            self.report({"WARNING"}, note)
        if not objects:
            return {"CANCELLED"}
        for obj in context.selected_objects:
            obj.select_set(False)
        for obj in objects:
            obj.select_set(True)
        context.view_layer.objects.active = objects[0]
        self.report({"INFO"}, f"TopStoc: imported {len(objects)} OFF file(s)")
        return {"FINISHED"}


def menu_entry(self, context):
    self.layout.operator(TOPSTOC_OT_import_off.bl_idname, text="OFF (.off)")


CLASSES = (TOPSTOC_OT_import_off,)


def register_menu():
    bpy.types.TOPBAR_MT_file_import.append(menu_entry)


def unregister_menu():
    bpy.types.TOPBAR_MT_file_import.remove(menu_entry)
