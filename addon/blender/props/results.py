"""Analysis results and overlay settings stored in .blend files.

Results live on the object (``obj.topstoc.topology``, ``obj.topstoc.metrics``), so undo and
redo restore them together with the mesh they describe, and they survive saving. Vertex-id
lists (loops, boundary and generator edges, per-face errors) are ID-property arrays on the
same property groups; topstoc.blender.analysis.topology and .metrics read and write them. Their keys
must differ from the RNA property names (RNA properties are stored under their own names):
"generator_edges", "boundary_vertices", "nonmanifold_edge_ids", "nonmanifold_vertex_ids",
"face_error", and "vertices" on each loop.
"""

from __future__ import annotations

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

LOOP_KINDS = [
    ("HANDLE", "Handle", "Goes around a handle, like a ring on a finger (yellow); cutting it opens the handle"),
    ("TUNNEL", "Tunnel", "Goes through a handle's hole, like a thread through a ring (turquoise)"),
    ("BOUNDARY", "Boundary", "The rim of an open hole (red vertices); Fill closes it"),
]
STATES = [
    ("NONE", "None", "Not analysed yet"),
    ("OK", "OK", "Up to date"),
    ("ERROR", "Error", "The last run failed; the message says why"),
]


def _redraw(_self, context):
    """Property update: redraw every 3D view (overlays and panels follow the settings)."""
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _overlay_switch(name: str, default: bool, description: str):
    """A setting that turns one overlay on or off (the 3D views redraw)."""
    return BoolProperty(name=name, default=default, update=_redraw, description=description)


class _Invariants:
    """What a component and the whole mesh both report (a mixin: Blender registers the
    properties of a property group's bases too)."""

    vertices: IntProperty(name="Vertices")
    edges: IntProperty(name="Edges")
    faces: IntProperty(name="Faces")
    triangles: IntProperty(name="Triangles")
    betti0: IntProperty(name="β0")
    betti1: IntProperty(name="β1")
    betti2: IntProperty(name="β2")
    boundary_loops: IntProperty(name="Boundary Loops")
    summary: StringProperty(name="Summary")


class TOPSTOC_PG_component(_Invariants, bpy.types.PropertyGroup):
    """Invariants of one connected component (counts in Blender's terms: polygons, edges)."""

    euler: IntProperty(name="Euler Characteristic")
    genus: IntProperty(name="Genus", description="-1 where undefined (non-manifold, non-orientable)")
    closed: BoolProperty(name="Closed")
    manifold: BoolProperty(name="Manifold")
    orientable: BoolProperty(name="Orientable")


class TOPSTOC_PG_loop(bpy.types.PropertyGroup):
    """A handle, tunnel or boundary loop; its vertex ids are the ID property ``"vertices"``."""

    kind: EnumProperty(name="Kind", items=LOOP_KINDS)
    component: IntProperty(name="Component")
    length: FloatProperty(name="Length", subtype="DISTANCE")
    relative: FloatProperty(name="Size", description="Length as a fraction of the bounding box's diagonal")
    num_edges: IntProperty(name="Edges")
    fillable: BoolProperty(name="Fillable", default=True)


class TOPSTOC_PG_topology(_Invariants, bpy.types.PropertyGroup):
    """Topology of an object's mesh (the Topology panel's data)."""

    state: EnumProperty(name="State", items=STATES, default="NONE")
    message: StringProperty(name="Message", description="Why the last analysis failed")
    stamp: StringProperty(name="Connectivity Fingerprint")
    seconds: FloatProperty(name="Analysis Time", subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE")
    revision: IntProperty(name="Revision", description="Changes whenever the results change")

    euler: IntProperty(name="χ")
    genus: IntProperty(name="Genus", description="Sum over the components; -1 if any is undefined")
    nonmanifold_edges: IntProperty(name="Non-Manifold Edges")
    nonmanifold_vertices: IntProperty(name="Non-Manifold Vertices")
    isolated_vertices: IntProperty(name="Isolated Vertices")
    duplicate_triangles: IntProperty(name="Duplicate Triangles")
    components: CollectionProperty(type=TOPSTOC_PG_component)
    component_index: IntProperty(name="Component")

    loops: CollectionProperty(type=TOPSTOC_PG_loop)
    loop_index: IntProperty(name="Active Loop", update=_redraw)
    loops_state: EnumProperty(name="Loop Search", items=STATES, default="NONE")
    loops_message: StringProperty(name="Loop Search Result")
    loops_stamp: StringProperty(name="Fingerprint of the Searched Mesh")
    loops_seconds: FloatProperty(name="Loop Search Time", subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE")
    edit_state: EnumProperty(name="Last Edit", items=STATES, default="NONE")
    edit_message: StringProperty(name="Last Edit Result")


class TOPSTOC_PG_metrics(bpy.types.PropertyGroup):
    """Hausdorff distance to a reference (usually the original) and triangle quality."""

    state: EnumProperty(name="State", items=STATES, default="NONE")
    message: StringProperty(name="Message")
    reference: PointerProperty(name="Original", type=bpy.types.Object,
                               poll=lambda self, obj: obj.type == "MESH",
                               description="The mesh this one is compared with (default: the object it was "
                                           "decimated from)")
    samples: IntProperty(name="Samples", default=200_000, min=1000, soft_max=5_000_000,
                         description="About how many points to sample on the original")
    stamp: StringProperty(name="Fingerprint of Both Meshes")
    seconds: FloatProperty(name="Measuring Time", subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE")
    revision: IntProperty(name="Revision")
    diagonal: FloatProperty(name="Diagonal", subtype="DISTANCE")
    symmetric_max: FloatProperty(name="Max", subtype="DISTANCE")
    symmetric_mean: FloatProperty(name="Mean", subtype="DISTANCE")
    symmetric_rms: FloatProperty(name="RMS", subtype="DISTANCE")
    forward_max: FloatProperty(name="Max", subtype="DISTANCE")
    forward_mean: FloatProperty(name="Mean", subtype="DISTANCE")
    forward_rms: FloatProperty(name="RMS", subtype="DISTANCE")
    backward_max: FloatProperty(name="Max", subtype="DISTANCE")
    backward_mean: FloatProperty(name="Mean", subtype="DISTANCE")
    backward_rms: FloatProperty(name="RMS", subtype="DISTANCE")
    aspect_mean: FloatProperty(name="Aspect Ratio Mean")
    aspect_max: FloatProperty(name="Aspect Ratio Max")
    degenerate: IntProperty(name="Degenerate Triangles")


class TOPSTOC_PG_overlays(bpy.types.PropertyGroup):
    """Which overlays the 3D views draw (scene-wide), and how."""

    show_handles: _overlay_switch("Handle Loops", True, "Draw handle loops (yellow)")
    show_tunnels: _overlay_switch("Tunnel Loops", True, "Draw tunnel loops (turquoise)")
    show_generators: _overlay_switch("Generator Edges", True, "Draw the 2g unpaired (generator) edges (pink)")
    show_boundary: _overlay_switch("Boundary Vertices", True, "Draw the vertices on boundary loops (red)")
    show_nonmanifold: _overlay_switch("Non-Manifold", True, "Draw non-manifold edges and vertices (orange)")
    show_samples: _overlay_switch("Show Kept Vertices", False,
                                  "Draw the sampled vertices of the last decimation (blue)")
    show_clusters: _overlay_switch("Show Regions", False, "Colour the original by the clusters of the last "
                                   "decimation (red: faces that became output triangles)")
    show_error: _overlay_switch("Error Colours", False, "Colour the decimated mesh by its Hausdorff error per face")
    error_scale: FloatProperty(name="Red At", default=0.0, min=0.0, soft_max=5.0, precision=3, update=_redraw,
                               description="The error shown red, in % of the original's diagonal; 0: the "
                                           "largest error measured")
    line_width: FloatProperty(name="Line Width", default=3.0, min=1.0, max=20.0, update=_redraw)
    active_width: FloatProperty(name="Active Loop Width", default=7.0, min=1.0, max=30.0, update=_redraw)
    point_size: FloatProperty(name="Point Size", default=5.0, min=1.0, max=30.0, update=_redraw)
    marker_size: FloatProperty(name="Small Loop Ring", default=28.0, min=0.0, max=200.0, update=_redraw,
                               description="A loop smaller than this on screen (pixels) gets a ring this wide "
                                           "around it, drawn over everything, so it can be found at any zoom "
                                           "(0: no rings)")


CLASSES = (TOPSTOC_PG_component, TOPSTOC_PG_loop, TOPSTOC_PG_topology, TOPSTOC_PG_metrics, TOPSTOC_PG_overlays)
