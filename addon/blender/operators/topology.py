"""Topology operators (thesis 4.2): analyse, find handles and tunnels (threaded, cancellable),
step through the loop list, select / cut / remove the active loop, fill holes, delete faces.

Every editing operator works from Object or Edit Mode (Edit Mode is left and re-entered around
the edit, so Blender's own mesh data is current), can be undone, and ends with a re-analysis.
Bad input (a non-manifold mesh, a refused tetrahedralization, an empty selection) is reported
in the status bar and the panel; the mesh is changed only after an edit fully succeeded.
"""

from __future__ import annotations

import threading

import bpy
import numpy as np
from bpy.props import EnumProperty

from ...core.api import edit
from ..analysis import topology as analysis
from ..io import mesh_access, mesh_read, edge_flags, mesh_edit
from ..preview import watch
from . import polls
from ...core.support.errors import TopStocError

#: Searches running in the background, by object name (the panel shows their progress).
running: dict = {}


def cancel_all() -> None:
    """Asks every running search to stop (on unregister: their modal handlers go away)."""
    for search in running.values():
        search.cancelled = True
    running.clear()


def _mesh_object(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "MESH" else None


def _object_or_edit_mode(context) -> bool:
    obj = _mesh_object(context)
    return obj is not None and context.mode in {"OBJECT", "EDIT_MESH"} and obj.name not in running


def _why_not_editable(context):
    """Reason the topology tools cannot run now (None: they can)."""
    reason = polls.active_mesh(context)
    if reason is None and context.mode not in {"OBJECT", "EDIT_MESH"}:
        reason = "Switch to Object or Edit Mode first"
    if reason is None and context.active_object.name in running:
        reason = "A loop search is running on this object (Esc cancels it)"
    return reason


class _ObjectModeSection:
    """Leaves Edit Mode for the duration of a block (Blender syncs the mesh data on the way out)."""

    def __init__(self, obj):
        self.obj = obj
        self.was_edit = obj.mode == "EDIT"

    def __enter__(self):
        if self.was_edit:
            bpy.ops.object.mode_set(mode="OBJECT")
        return self

    def __exit__(self, *_exc):
        if self.was_edit:
            bpy.ops.object.mode_set(mode="EDIT")
        return False


def _redraw_panels(context) -> None:
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


class TOPSTOC_OT_analyse(bpy.types.Operator):
    """Count the pieces, handles (genus) and open holes of the mesh and check that it is \
manifold: V, E, F, Betti numbers, χ per piece (fast)"""

    bl_idname = "topstoc.analyse"
    bl_label = "Analyse"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, _why_not_editable(context))

    def execute(self, context):
        obj = _mesh_object(context)
        try:
            with _ObjectModeSection(obj):
                analysis.analyse(obj)
        except analysis.AnalysisError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        t = obj.topstoc.topology
        self.report({"INFO"}, f"TopStoc: {t.summary} ({1000 * t.seconds:.0f} ms)")
        return {"FINISHED"}


class TOPSTOC_OT_find_loops(bpy.types.Operator):
    """Find the loops around (handle) and through (tunnel) each handle of the closed pieces, \
to cut or remove unwanted handles before decimating or printing. Runs in the background; Esc cancels"""

    bl_idname = "topstoc.find_loops"
    bl_label = "Find Handles & Tunnels"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh_in_object_mode(context)
        if reason is None and context.active_object.name in running:
            reason = "A loop search is already running on this object"
        return polls.refuse(cls, reason)

    def execute(self, context):  # synchronous: background mode, scripts
        obj = _mesh_object(context)
        try:
            message = analysis.find_loops(obj)
        except analysis.AnalysisError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"TopStoc: {message}")
        return {"FINISHED"}

    def invoke(self, context, event):
        if context.window is None or bpy.app.background:
            return self.execute(context)
        obj = _mesh_object(context)
        try:
            self.search = analysis.start_search(obj)
        except analysis.AnalysisError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.object_name = obj.name
        running[obj.name] = self.search
        # Started by the first modal event, after invoke has returned to Blender: a thread running
        # while bpy.ops with a context override is still in Blender's C code crashes Blender 3.4
        # (see preview.PreviewSession.begin).
        self.thread = threading.Thread(target=self.search.run, name="TopStoc loops", daemon=True)
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self.timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _status(self, context, text) -> None:
        if context.area is not None:
            context.area.header_text_set(text)

    def modal(self, context, event):
        search = self.search
        if self.thread.ident is None:
            self.thread.start()
        if event.type == "ESC" and event.value == "PRESS":
            search.cancelled = True  # the engine stops at its next progress report
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        context.window_manager.progress_update(int(100 * search.fraction))
        self._status(context, f"TopStoc: {search.stage} {100 * search.fraction:.0f} %"
                              f"{' (cancelling)' if search.cancelled else ''}   Esc: cancel")
        _redraw_panels(context)
        if self.thread.is_alive():
            return {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.event_timer_remove(self.timer)
        wm.progress_end()
        self._status(context, None)
        running.pop(self.object_name, None)
        obj = bpy.data.objects.get(self.object_name)
        if obj is None:
            return {"CANCELLED"}
        try:
            message = analysis.finish_search(obj, search)
        except analysis.AnalysisError as error:
            self.report({"WARNING"} if search.error == "cancelled" else {"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"TopStoc: {message}")
        _redraw_panels(context)
        return {"FINISHED"}


class TOPSTOC_OT_loop_step(bpy.types.Operator):
    """Make the previous or next loop of the list active"""

    bl_idname = "topstoc.loop_step"
    bl_label = "Step Through Loops"

    direction: EnumProperty(items=[("PREVIOUS", "Previous", ""), ("NEXT", "Next", "")], default="NEXT")

    @classmethod
    def poll(cls, context):
        reason = polls.active_mesh(context)
        if reason is None and not len(context.active_object.topstoc.topology.loops):
            reason = "No loops yet: press Find Loops first"
        return polls.refuse(cls, reason)

    def execute(self, context):
        topology = _mesh_object(context).topstoc.topology
        step = 1 if self.direction == "NEXT" else -1
        topology.loop_index = (topology.loop_index + step) % len(topology.loops)
        return {"FINISHED"}


class _LoopOperator:
    @classmethod
    def poll(cls, context):
        reason = _why_not_editable(context)
        if reason is None:
            loop = analysis.active_loop(context.active_object)
            if loop is None:
                reason = "No active loop: press Find Loops, then pick one in the list"
            elif not cls.kinds_ok(loop.kind):
                reason = cls.kind_message
        return polls.refuse(cls, reason)

    @staticmethod
    def kinds_ok(kind) -> bool:
        return True

    kind_message = ""

    def edit_active_loop(self, context, edit_function, verb: str) -> set:
        """Runs ``edit_function(vertices, triangles, loop_ids)`` on the active loop."""
        obj = _mesh_object(context)
        index = obj.topstoc.topology.loop_index
        ids = _loop_ids(obj)
        return run_edit(self, context, lambda o, a: edit_function(a.vertices, a.triangles, ids),
                        dropped=index, verb=f"{verb} {analysis.active_loop(obj).name}", uses_loop=True)


class _HandleLoopOperator(_LoopOperator):
    """An edit of the handle a loop goes around or through: a boundary loop has none."""

    @staticmethod
    def kinds_ok(kind) -> bool:
        return kind != "BOUNDARY"

    kind_message = "The active loop is a boundary (a hole's rim): fill it with Fill Holes instead"


def run_edit(operator, context, compute, dropped: int = -1, verb: str = "edited", uses_loop: bool = False,
             carry: bool = True) -> set:
    """Runs ``compute(obj, arrays) -> EditResult`` on the active mesh, writes it, re-analyses.

    Nothing is changed when ``compute`` raises (the message goes to the status bar).
    ``uses_loop``: ``compute`` uses a stored loop, which a changed mesh invalidates.
    ``carry``: keep the searched loops whose edges are still there (all but ``dropped``); an
    edit that removes many handles says False (a cut loop's edges stay, as a patch's rim).
    """
    obj = _mesh_object(context)
    topology = obj.topstoc.topology

    def refuse(message: str) -> set:
        topology.edit_state, topology.edit_message = "ERROR", message  # shown in the panel
        operator.report({"ERROR"}, f"TopStoc: {message}")
        return {"CANCELLED"}

    with _ObjectModeSection(obj):
        if not analysis.is_current(obj, fresh=True):
            if uses_loop:
                return refuse(f"'{obj.name}' changed since its analysis; press Analyse")
            try:
                analysis.analyse(obj)  # the loop list must describe this mesh
            except analysis.AnalysisError as error:
                return refuse(str(error))
        try:
            arrays = mesh_read.read_mesh(obj.data)
            result = compute(obj, arrays)
            carried = analysis.carry_loops(obj, result, dropped) if carry else []
            mesh_edit.apply_edit(obj, arrays, result)
        except ValueError as error:  # EditError or an engine refusal
            return refuse(f"'{obj.name}': {error}")
        watch.bump(obj)
        try:
            analysis.analyse(obj, carried_loops=carried)
        except analysis.AnalysisError as error:
            operator.report({"WARNING"}, str(error))
    topology = obj.topstoc.topology
    topology.edit_state, topology.edit_message = "OK", f"{verb[0].upper()}{verb[1:]}; now {topology.summary}"
    operator.report({"INFO"}, f"TopStoc: {verb}; now {topology.summary}")
    return {"FINISHED"}


def _loop_ids(obj) -> np.ndarray:
    return analysis.loop_vertices(analysis.active_loop(obj))


class TOPSTOC_OT_select_loop(_LoopOperator, bpy.types.Operator):
    """Select the active loop's edges (in Edit Mode)"""

    bl_idname = "topstoc.select_loop"
    bl_label = "Select Loop"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        import bmesh

        obj = _mesh_object(context)
        with _ObjectModeSection(obj):
            if not analysis.is_current(obj, fresh=True):
                self.report({"ERROR"}, "TopStoc: the mesh changed since the analysis; press Analyse")
                return {"CANCELLED"}
            mesh = obj.data
            ids = _loop_ids(obj)
            edges = mesh_access.read_indices(mesh.edges, "vertices", len(mesh.edges), 2).astype(np.int64)
            n = len(mesh.vertices)
            keys = np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1])
            following = np.roll(ids, -1)
            loop_keys = np.minimum(ids, following) * n + np.maximum(ids, following)
            edge_ids = np.flatnonzero(np.isin(keys, loop_keys)).tolist()
            missing = len(set(loop_keys.tolist())) - len(edge_ids)
        # Select in Edit Mode (bmesh keeps the element order of the mesh), so the selection is
        # part of the edit-mode undo step and Ctrl+Z gives the previous one back.
        if obj.mode != "EDIT":
            bpy.ops.object.mode_set(mode="EDIT")
        context.tool_settings.mesh_select_mode = (False, True, False)
        bm = bmesh.from_edit_mesh(obj.data)
        for elements in (bm.verts, bm.edges, bm.faces):
            for element in elements:
                element.select = False
        bm.edges.ensure_lookup_table()
        bm.verts.ensure_lookup_table()
        for index in edge_ids:
            bm.edges[index].select_set(True)
        for index in ids.tolist():  # diagonals of polygons are not edges: select their vertices
            bm.verts[index].select = True
        bm.select_flush_mode()
        bmesh.update_edit_mesh(obj.data, loop_triangles=False, destructive=False)
        text = f"TopStoc: selected {len(edge_ids)} edges of {analysis.active_loop(obj).name}"
        if missing:
            text += f" ({missing} run along polygon diagonals: their vertices are selected)"
        self.report({"INFO"}, text)
        return {"FINISHED"}


class TOPSTOC_OT_cut_loop(_HandleLoopOperator, bpy.types.Operator):
    """Cut the surface open along the active loop: the handle becomes two holes with rims \
(genus -1, two new boundary loops)"""

    bl_idname = "topstoc.cut_loop"
    bl_label = "Cut Along Loop"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        return self.edit_active_loop(context, edit.cut_along_loop, "cut along")


class TOPSTOC_OT_remove_loop(_HandleLoopOperator, bpy.types.Operator):
    """Remove the handle the active loop goes around or through: cut along it and fill both \
holes (the genus drops by one; e.g. a scan's tiny unwanted handle)"""

    bl_idname = "topstoc.remove_loop"
    bl_label = "Remove"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        return self.edit_active_loop(context, edit.remove_handle, "removed")


FILL_MODES = [("ACTIVE", "Active Loop", "Fill the active boundary loop"),
              ("SELECTED", "Selected", "Fill every hole with a selected boundary edge"),
              ("ALL", "All", "Fill every hole that can be filled")]


class TOPSTOC_OT_fill_holes(bpy.types.Operator):
    """Close open holes, as a watertight 3D print needs (planar projection and 2D \
triangulation, robust fallbacks)"""

    bl_idname = "topstoc.fill_holes"
    bl_label = "Fill Holes"
    bl_options = {"REGISTER", "UNDO"}

    mode: EnumProperty(name="Holes", items=FILL_MODES, default="ALL")

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, _why_not_editable(context))

    def execute(self, context):
        obj = _mesh_object(context)
        mode = self.mode
        if mode == "SELECTED" and context.mode != "EDIT_MESH":  # Object Mode hides the selection
            self.report({"ERROR"}, "TopStoc: select the holes' edges in Edit Mode")
            return {"CANCELLED"}
        if mode == "ACTIVE":
            loop = analysis.active_loop(obj)
            if loop is None or loop.kind != "BOUNDARY":
                self.report({"ERROR"}, "TopStoc: the active loop is not a boundary loop")
                return {"CANCELLED"}
            ids = analysis.loop_vertices(loop)
            return run_edit(self, context, lambda o, a: edit.fill_loops(a.vertices, a.triangles, [ids]),
                            verb=f"filled {loop.name}", uses_loop=True)

        def compute(o, arrays):
            holes = edit.boundary_loops(arrays.vertices, arrays.triangles)
            if not holes:
                raise TopStocError("the mesh has no holes")
            if mode == "ALL":
                return edit.fill_holes(arrays.vertices, arrays.triangles, skip_unfillable=True)
            selected = edge_flags.read_element_flag(o.data, "POINT", "select")
            picked = [i for i, hole in enumerate(holes)
                      if (selected[hole.vertices] & selected[np.roll(hole.vertices, -1)]).any()]
            if not picked:
                raise TopStocError("no hole has a selected boundary edge")
            return edit.fill_holes(arrays.vertices, arrays.triangles, holes=picked)

        return run_edit(self, context, compute, verb="holes filled")


class TOPSTOC_OT_delete_faces(bpy.types.Operator):
    """Delete the selected faces (and the vertices only they used)"""

    bl_idname = "topstoc.delete_faces"
    bl_label = "Delete Selected Faces"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        # only a selection the user sees: in Object Mode it is hidden (an importer's may be everything)
        reason = _why_not_editable(context)
        if reason is None and context.mode != "EDIT_MESH":
            reason = "Select the faces to delete in Edit Mode"
        return polls.refuse(cls, reason)

    def execute(self, context):
        def compute(o, arrays):
            selected = edge_flags.read_element_flag(o.data, "FACE", "select")
            if not selected.any():
                raise TopStocError("no faces are selected")
            return edit.delete_faces(arrays.vertices, arrays.triangles, selected[arrays.triangle_polygon])

        return run_edit(self, context, compute, verb="faces deleted")


CLASSES = (TOPSTOC_OT_analyse, TOPSTOC_OT_find_loops, TOPSTOC_OT_loop_step, TOPSTOC_OT_select_loop,
           TOPSTOC_OT_cut_loop, TOPSTOC_OT_remove_loop, TOPSTOC_OT_fill_holes, TOPSTOC_OT_delete_faces)
