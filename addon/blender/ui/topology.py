"""Topology panel (thesis 4.2.1): invariants, components, loop list, editing tools, overlays."""

from __future__ import annotations

import bpy

from ..analysis import clean_plan, topology as analysis
from .topology_help import HELP
from ..operators.topology import running
from .panels import _ClosedPanel, _MeshPanel, _Panel, _mesh, wrapped

KIND_ICONS = {"HANDLE": "MOD_CURVE", "TUNNEL": "MOD_SCREW", "BOUNDARY": "MOD_EDGESPLIT"}


def invariant_rows(topology) -> list:
    """(label, value) pairs of the panel's table, in Blender's counts (polygons, edges)."""
    return [(label, value) for label, value, _topic in help_rows(topology)]


def help_rows(topology) -> list:
    """(label, value, help topic) rows of the panel's table (topology_help.HELP)."""
    genus = "undefined" if topology.genus < 0 else str(topology.genus)
    rows = [("Vertices", f"{topology.vertices:,}", "vertices"), ("Edges", f"{topology.edges:,}", "edges"),
            ("Faces", f"{topology.faces:,}", "faces"), ("Triangles", f"{topology.triangles:,}", "triangles"),
            ("β0 / β1 / β2", f"{topology.betti0} / {topology.betti1} / {topology.betti2}", "betti"),
            ("χ", str(topology.euler), "euler"), ("Genus", genus, "genus"),
            ("Components", str(len(topology.components)), "components"),
            ("Holes", str(topology.boundary_loops), "boundary"),
            ("Non-Manifold", "", None),  # a heading: "Non-Manifold Vertices: 0" does not fit the sidebar
            ("   Edges", str(topology.nonmanifold_edges), "nonmanifold_edges"),
            ("   Vertices", str(topology.nonmanifold_vertices), "nonmanifold_vertices"),
            ("Loose Vertices", str(topology.isolated_vertices), "isolated")]
    if topology.duplicate_triangles:
        rows.append(("Repeated Faces", str(topology.duplicate_triangles), "faces"))
    return rows


def plain_summary(topology) -> str:
    """One info line an artist can act on."""
    if topology.faces == 0:
        return "The mesh is empty: no faces"
    pieces = len(topology.components)
    parts = [f"{pieces} piece{'s' if pieces != 1 else ''}"]
    if topology.genus > 0:
        parts.append(f"{topology.genus} handle{'s' if topology.genus != 1 else ''} (donut-like holes through it)")
    if topology.boundary_loops:
        parts.append(f"{topology.boundary_loops} open hole{'s' if topology.boundary_loops != 1 else ''}")
    bad = topology.nonmanifold_edges + topology.nonmanifold_vertices
    if bad:
        parts.append(f"{bad} non-manifold spots")
    printable = not topology.boundary_loops and not bad
    verdict = "closed and manifold: ready to print" if printable else "not watertight: fix before printing"
    return ", ".join(parts) + f"; {verdict}"


def help_button(layout, topic: str) -> None:
    layout.operator("topstoc.explain", text="", icon="QUESTION", emboss=False).topic = topic


def _table(layout, rows) -> None:
    """One "name: value" line per row (a help button after it): two columns would cut big counts."""
    col = layout.column(align=True)
    for row in rows:
        label, value = row[0], row[1]
        line = col.row(align=True)
        line.label(text=f"{label}: {value}" if value else label)
        if len(row) > 2 and row[2]:
            help_button(line, row[2])
        elif len(row) > 2:
            line.label(text="", icon="BLANK1")


class TOPSTOC_UL_components(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        genus = "genus undefined" if item.genus < 0 else f"genus {item.genus}"
        layout.label(text=f"Piece {index + 1}: {genus}", icon="MESH_DATA" if item.manifold else "ERROR")


class TOPSTOC_UL_loops(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        warning = item.kind == "BOUNDARY" and not item.fillable
        layout.label(text=f"{item.name}: {loop_size(item)}", icon="ERROR" if warning else KIND_ICONS.get(item.kind, "DOT"))


def loop_size(item) -> str:
    """A loop's size as the list shows it: its length as a percentage of the diagonal (the unit
    of the clean-up's sizes) and its edge count."""
    return f"{100 * item.relative:.2g} %, {item.num_edges} edges"


class TOPSTOC_PT_topology(_MeshPanel, bpy.types.Panel):
    bl_label = "Topology"
    bl_order = 10

    def draw_mesh(self, context, layout, obj):
        topology = obj.topstoc.topology
        col = layout.column(align=True)  # side by side, "Find Loops" and its icon have too little width
        col.operator("topstoc.analyse", icon="VIEWZOOM")
        col.operator("topstoc.find_loops", text="Find Loops", icon="MOD_SCREW")
        search = running.get(obj.name)
        if search is not None:
            layout.label(text=f"{search.stage}: {100 * search.fraction:.0f} %"
                              f"{' (cancelling)' if search.cancelled else ' (Esc cancels)'}", icon="TIME")
        if topology.state == "ERROR":
            wrapped(layout, context, topology.message, "ERROR")
            return
        if topology.state != "OK":
            layout.label(text="Not analysed yet", icon="INFO")
            return
        if context.mode == "EDIT_MESH":
            wrapped(layout, context, "Figures as of the last mode switch", "EDITMODE_HLT")
        elif not analysis.is_current(obj):
            layout.label(text="The mesh changed: Analyse again", icon="ERROR")
        wrapped(layout, context, plain_summary(topology), "INFO")
        wrapped(layout, context, topology.summary)
        _table(layout.box(), help_rows(topology))
        row = layout.row()
        row.label(text="Why it matters")
        help_button(row, "why")
        layout.label(text=f"Analysed in {1000 * topology.seconds:.0f} ms")


def _analysed(context):
    """The active mesh's topology results once it has been analysed, else None."""
    obj = _mesh(context)
    return obj.topstoc.topology if obj is not None and obj.topstoc.topology.state == "OK" else None


class _AnalysedPanel(_Panel):
    """A sub-panel shown once the active mesh has been analysed: draws its results."""

    @classmethod
    def poll(cls, context):
        return _analysed(context) is not None

    def draw(self, context):
        topology = _analysed(context)
        if topology is not None:
            self.draw_analysed(context, self.layout, topology)


class TOPSTOC_PT_topology_components(_AnalysedPanel, _ClosedPanel, bpy.types.Panel):
    bl_label = "Components"
    bl_parent_id = "TOPSTOC_PT_topology"

    def draw_analysed(self, context, layout, topology):
        layout.template_list("TOPSTOC_UL_components", "", topology, "components", topology, "component_index",
                             rows=3)
        if 0 <= topology.component_index < len(topology.components):
            c = topology.components[topology.component_index]
            _table(layout.box(), [
                ("Vertices", f"{c.vertices:,}"), ("Edges", f"{c.edges:,}"), ("Faces", f"{c.faces:,}"),
                ("β0 / β1 / β2", f"{c.betti0} / {c.betti1} / {c.betti2}"), ("χ", str(c.euler)),
                ("Genus", "undefined" if c.genus < 0 else str(c.genus)), ("Holes", str(c.boundary_loops)),
                ("Closed", "yes" if c.closed else "no"), ("Manifold", "yes" if c.manifold else "no"),
                ("Orientable", "yes" if c.orientable else "no")])


class TOPSTOC_PT_topology_loops(_AnalysedPanel, bpy.types.Panel):
    bl_label = "Loops"
    bl_parent_id = "TOPSTOC_PT_topology"

    def draw_analysed(self, context, layout, topology):
        obj = topology.id_data  # the object the results are stored on
        if topology.loops_message:
            wrapped(layout, context, topology.loops_message,
                    "ERROR" if topology.loops_state == "ERROR" else "INFO")
        if not topology.loops:
            layout.label(text="No loops yet: press Find Loops")
            return
        layout.template_list("TOPSTOC_UL_loops", "", topology, "loops", topology, "loop_index", rows=4)
        active = analysis.active_loop(obj)
        row = layout.row(align=True)
        row.operator("topstoc.loop_step", text="", icon="TRIA_LEFT").direction = "PREVIOUS"
        row.operator("topstoc.loop_step", text="", icon="TRIA_RIGHT").direction = "NEXT"
        if active is None:
            return
        row.separator()
        row.operator("topstoc.frame_loop", text="Frame")
        row.operator("topstoc.select_loop", text="Select")
        row = layout.row(align=True)  # a second row: four buttons beside the arrows are cut
        if active.kind == "BOUNDARY":
            row.operator("topstoc.fill_holes", text="Fill").mode = "ACTIVE"
        else:
            row.operator("topstoc.cut_loop", text="Cut")
            row.operator("topstoc.remove_loop", text="Remove")
        row = layout.row()
        row.label(text=f"{active.num_edges} edges, length {active.length:.4g}")  # the list row has its %
        help_button(row, {"HANDLE": "handle", "TUNNEL": "tunnel"}.get(active.kind, "boundary_loop"))
        wrapped(layout, context, HELP[{"HANDLE": "handle", "TUNNEL": "tunnel"}.get(active.kind, "boundary_loop")])


class TOPSTOC_PT_topology_edit(_Panel, bpy.types.Panel):
    bl_label = "Edit"
    bl_parent_id = "TOPSTOC_PT_topology"

    def draw(self, context):
        layout = self.layout
        obj = _mesh(context)
        if obj is not None and obj.topstoc.topology.edit_message:
            topology = obj.topstoc.topology
            wrapped(layout, context, topology.edit_message, "ERROR" if topology.edit_state == "ERROR" else "CHECKMARK")
        col = layout.column(align=True)
        col.operator("topstoc.fill_holes", text="Fill Selected Holes", icon="MOD_SOLIDIFY").mode = "SELECTED"
        col.operator("topstoc.fill_holes", text="Fill All Holes", icon="MOD_SOLIDIFY").mode = "ALL"
        col.operator("topstoc.delete_faces", icon="TRASH")
        # the full name, "... Small Handles and Holes", does not fit the sidebar (the tooltip says it)
        layout.operator("topstoc.clean", text="Clean Up Small Flaws", icon="MOD_SMOOTH")
        shown = clean_plan.shown(obj) if obj is not None else None
        if shown is not None:  # the clean-up waits for Enter or Esc
            box = layout.box()
            wrapped(box, context, f"Preview: {shown.summary()}", "HIDE_OFF")
            box.label(text="Green: removed, violet: left")
            box.label(text="Enter: apply, Esc: cancel")


class TOPSTOC_PT_topology_overlays(_ClosedPanel, bpy.types.Panel):
    bl_label = "Overlays"
    bl_parent_id = "TOPSTOC_PT_topology"

    def draw(self, context):
        layout = self.layout
        show = context.scene.topstoc.overlays
        col = layout.column(align=True)
        for name in ("show_handles", "show_tunnels", "show_generators", "show_boundary", "show_nonmanifold"):
            col.prop(show, name)
        col = layout.column(align=True)  # no label column: "Active Loop Width" does not fit one
        col.prop(show, "line_width")
        col.prop(show, "active_width")
        col.prop(show, "point_size")
        col.prop(show, "marker_size")


CLASSES = (TOPSTOC_UL_components, TOPSTOC_UL_loops, TOPSTOC_PT_topology, TOPSTOC_PT_topology_components,
           TOPSTOC_PT_topology_loops, TOPSTOC_PT_topology_edit, TOPSTOC_PT_topology_overlays)
