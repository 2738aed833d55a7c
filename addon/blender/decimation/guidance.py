"""Guidance sources of a Blender object -> engine arguments (u, regions, borders, view, boxes).

The rules that turn each source into ``u`` and combine them are in topstoc.core.api.guidance;
this module only reads Blender data. Problems with the user's settings (a vertex group or
colour attribute that does not exist, no camera) raise GuidanceError with a message for the
status bar; nothing is modified.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
from typing import Callable, List, Optional

import bpy
import numpy as np
from mathutils import Matrix, Vector

from ...core.api import guidance as rules
from ...core.carry.appearance import Appearance, appearance_attributes
from ...core.carry.attributes import hard_normal_edges, uv_seam_edges
from ...core.api.decimate import Box, View
from ...core.support.errors import TopStocError
from ..io import mesh_read, mesh_attributes, edge_flags
from ..props import DEFAULT_COLOR_LAYER


class GuidanceError(TopStocError):
    """A guidance setting that cannot be honoured (message names the setting)."""


@dataclass
class EngineGuidance:
    """What the engine receives besides the target; ``sources`` says what was used."""

    guidance: Optional[np.ndarray] = None
    regions: Optional[np.ndarray] = None
    borders: Optional[np.ndarray] = None
    view: Optional[View] = None
    boxes: List[Box] = field(default_factory=list)
    sources: List[str] = field(default_factory=list)
    #: the look to keep (active UV map, colours), made when a decimation needs it (pipeline.engine_job)
    appearance: Callable[[], Appearance] = Appearance
    appearance_sources: List[str] = field(default_factory=list)  #: what ``appearance`` holds

    def layout_kwargs(self) -> dict:
        """The part that restoring from samples needs (the feature layout)."""
        return dict(regions=self.regions, borders=self.borders)

    def layout_digest(self) -> str:
        h = hashlib.blake2b(digest_size=16)
        for array in (self.regions, self.borders):
            h.update(b"-" if array is None else np.ascontiguousarray(array).tobytes())
        return h.hexdigest()


def _matrix(m: Matrix) -> np.ndarray:
    return np.array([list(row) for row in m], dtype=np.float64)


def read_color_guidance(mesh, name: str) -> np.ndarray:
    """u per vertex from a colour attribute (rules in topstoc.core.api.guidance)."""
    return _read_color(mesh, name)()


def _read_color(mesh, name: str) -> Callable[[], np.ndarray]:
    """Reads a colour attribute; returns the function giving u per vertex from it."""
    attribute = mesh.color_attributes.get(name)
    if attribute is None:
        raise GuidanceError(f"colour attribute '{name}' not found on mesh '{mesh.name}' "
                            "(paint it in Vertex Paint mode or use 'Add Guidance Layer')")
    count = len(mesh.vertices) if attribute.domain == "POINT" else len(mesh.loops)
    values, key = mesh_attributes.read_attribute(attribute, count)
    corner_vertex = mesh_read.corner_vertices(mesh) if attribute.domain == "CORNER" else None
    n = len(mesh.vertices)

    def guidance() -> np.ndarray:
        rgb = values[:, :3].astype(np.float64)
        if key == "color":
            rgb = rules.linear_to_srgb(rgb)
        if corner_vertex is not None:
            rgb = rules.corner_to_vertex_mean(n, corner_vertex, rgb)
        return rules.color_to_guidance(rgb)

    return guidance


def _read_borders(obj, settings, arrays: mesh_read.MeshArrays) -> Callable[[list], Optional[np.ndarray]]:
    """Reads seams, sharp edges and the hard edges of custom normals; returns the function giving
    the border edges (it appends what it found to the list of sources it is given). A hard edge is
    a border so that each side's output corners take that side's normals, as at a UV seam."""
    mesh = obj.data
    uv_maps = mesh_attributes.read_uv_maps(mesh) if settings.use_uv_seams else {}
    marked = edge_flags.read_edges(mesh, "use_seam") if settings.use_uv_seams else np.zeros((0, 2), np.int32)
    sharp = edge_flags.read_edges(mesh, "use_edge_sharp") if settings.use_sharp else np.zeros((0, 2), np.int32)
    normals = mesh_read.read_custom_normals(mesh) if settings.use_hard_normals else None

    def borders(sources: list) -> Optional[np.ndarray]:
        parts = []
        for name, uv in uv_maps.items():
            seams = uv_seam_edges(arrays.triangles, uv[arrays.triangle_loops])
            if len(seams):
                parts.append(seams)
                sources.append(f"UV seams of '{name}' ({len(seams)} edges)")
        if len(marked):
            parts.append(marked)
            sources.append(f"marked seams ({len(marked)} edges)")
        if len(sharp):
            parts.append(sharp)
            sources.append(f"sharp edges ({len(sharp)})")
        if normals is not None:
            hard = hard_normal_edges(arrays.triangles, normals[arrays.triangle_loops])
            if len(hard):
                parts.append(hard)
                sources.append(f"hard edges of the custom normals ({len(hard)} edges)")
        if not parts:
            return None
        # Only edges of triangles can be borders (loose edges carry no faces to separate).
        edges = rules.undirected_edges(arrays.triangles)
        found = rules.edges_in(edges, np.concatenate(parts))
        return found if len(found) else None

    return borders


def guidance_layers(obj) -> tuple:
    """Names of the colour layers that hold guidance paint, not the asset's look."""
    return _guidance_layer_names(obj.topstoc)


def _guidance_layer_names(settings) -> tuple:
    return (settings.color_attribute, DEFAULT_COLOR_LAYER)


def appearance_color(mesh, settings):
    """The colour attribute that is part of the asset's look: the active one, or the render one
    when the active one is the guidance paint layer; None if both are guidance (or there are none).
    Guidance paint (the object's painted-guidance layer, or the default layer's name) says where
    to keep detail, it is not appearance, so it never enters the cost."""
    guidance = _guidance_layer_names(settings)
    colors = mesh.color_attributes
    candidates = [colors.active_color]
    if 0 <= colors.render_color_index < len(colors):
        candidates.append(colors[colors.render_color_index])
    for attribute in candidates:
        if attribute is not None and attribute.name not in guidance:
            return attribute
    return None


def _read_appearance(obj, arrays: mesh_read.MeshArrays) -> tuple:
    """Reads the active UV map, the appearance colour (appearance_color) and the custom normals
    (mesh_read.read_custom_normals; normals Blender derives from the shape are left out, see
    core/carry/appearance.py); returns (the function giving the engine's attributes, what they hold).
    Colours enter as sRGB in [0, 1]."""
    mesh = obj.data
    names, uv, color, color_key, color_domain = [], None, None, None, None
    layer = mesh.uv_layers.active
    if layer is not None:
        uv = mesh_attributes.read_uv_map(mesh, layer.name)
        names.append(f"UV map '{layer.name}'")
    attribute = appearance_color(mesh, obj.topstoc)
    if attribute is not None and attribute.domain in ("POINT", "CORNER"):
        count = len(mesh.vertices) if attribute.domain == "POINT" else len(mesh.loops)
        read = mesh_attributes.read_attribute(attribute, count)
        if read is not None:
            color, color_key = read
            color_domain = attribute.domain
            names.append(f"colours '{attribute.name}'")
    normals = mesh_read.read_custom_normals(mesh)
    if normals is not None:
        names.append("custom normals")

    @functools.lru_cache(maxsize=1)
    def appearance() -> Appearance:
        if uv is None and color is None and normals is None:  # nothing to read the triangles for
            return Appearance()
        corner_uvs = None if uv is None else uv[arrays.triangle_loops]
        rgb = None
        if color is not None:
            rgb = color[:, :3].astype(np.float64)
            if color_key == "color":  # linear floats: compare colours as they look
                rgb = rules.linear_to_srgb(rgb)
            if color_domain == "CORNER":
                rgb = rgb[arrays.triangle_loops]
        corner_normals = None if normals is None else normals[arrays.triangle_loops]
        return appearance_attributes(arrays.triangles, corner_uvs, rgb, corner_normals)

    return appearance, names


def _boxes(obj, scene) -> List[Box]:
    world = obj.matrix_world
    boxes = []
    for box in sorted(scene.objects, key=lambda o: o.name):
        if box.type != "EMPTY" or box.empty_display_type != "CUBE" or not box.topstoc.box_enabled:
            continue
        if abs(box.matrix_world.determinant()) < 1e-30 or box.empty_display_size <= 0:
            raise GuidanceError(f"guidance box '{box.name}' has zero size")
        scale = Matrix.Scale(1.0 / box.empty_display_size, 4)
        world_to_box = scale @ box.matrix_world.inverted() @ world
        value = float(np.clip(box.topstoc.box_weight * scene.topstoc.box_strength, -1, 1))
        boxes.append(Box(_matrix(world_to_box), value))
    return boxes


def _camera_view(obj, scene, depsgraph) -> View:
    camera = scene.camera
    if camera is None:
        raise GuidanceError("view-dependent decimation needs a scene camera")
    render = scene.render
    to_local = obj.matrix_world.inverted()
    projection = camera.calc_matrix_camera(depsgraph, x=render.resolution_x, y=render.resolution_y,
                                           scale_x=render.pixel_aspect_x, scale_y=render.pixel_aspect_y)
    clip = projection @ camera.matrix_world.inverted() @ obj.matrix_world
    if camera.data.type == "ORTHO":
        direction = to_local.to_3x3() @ (camera.matrix_world.to_3x3() @ Vector((0.0, 0.0, -1.0)))
        return View(direction=list(direction), view_projection=_matrix(clip))
    eye = to_local @ camera.matrix_world.translation
    return View(eye=list(eye), view_projection=_matrix(clip))


def _viewport_view(obj, region_3d) -> View:
    if region_3d is None:
        raise GuidanceError("no 3D viewport to take the view from; use the scene camera")
    to_local = obj.matrix_world.inverted()
    clip = region_3d.perspective_matrix @ obj.matrix_world
    view_to_world = region_3d.view_matrix.inverted()
    if region_3d.is_perspective:
        return View(eye=list(to_local @ view_to_world.translation), view_projection=_matrix(clip))
    direction = to_local.to_3x3() @ (view_to_world.to_3x3() @ Vector((0.0, 0.0, -1.0)))
    return View(direction=list(direction), view_projection=_matrix(clip))


def gather(obj, arrays: mesh_read.MeshArrays, scene, depsgraph=None, region_3d=None) -> EngineGuidance:
    """Reads every enabled guidance source of ``obj`` into engine arguments."""
    return read(obj, arrays, scene, depsgraph, region_3d)()


def read(obj, arrays: mesh_read.MeshArrays, scene, depsgraph=None,
         region_3d=None) -> Callable[[], EngineGuidance]:
    """Reads every enabled guidance source of ``obj`` (Blender data: the main thread) and returns
    the function that turns what was read into engine arguments (numpy only: any thread; the
    live preview runs it on its worker). Settings that cannot be honoured raise GuidanceError
    here, while reading."""
    settings = obj.topstoc
    scene_settings = scene.topstoc
    n = len(arrays.vertices)
    names = []    # what each source is called, in order
    sources = []  # (function giving u, strength) per guidance source

    if settings.use_vertex_group:
        group = obj.vertex_groups.get(settings.vertex_group)
        if group is None:
            raise GuidanceError(f"vertex group '{settings.vertex_group}' not found on '{obj.name}'")
        weights, assigned = mesh_attributes.read_vertex_group(obj, group.index)
        mapping = settings.vertex_group_mapping
        sources.append((lambda: rules.vertex_group_guidance(weights, assigned, mapping),
                        settings.vertex_group_strength))
        names.append(f"vertex group '{group.name}'")
    if settings.use_color and settings.color_attribute:
        mesh = obj.data
        if mesh.color_attributes.get(settings.color_attribute) is not None:
            sources.append((_read_color(mesh, settings.color_attribute), settings.color_strength))
            names.append(f"painted '{settings.color_attribute}'")
        elif settings.color_attribute != DEFAULT_COLOR_LAYER:  # the default layer may not exist yet
            raise GuidanceError(f"colour attribute '{settings.color_attribute}' not found on '{obj.name}'")
    material_weights = None
    if settings.use_materials and len(arrays.polygon_material):
        material_weights = list(settings.material_weights)[:max(len(obj.material_slots), 1)]
        material_strength = settings.material_strength
    borders = _read_borders(obj, settings, arrays)
    appearance, appearance_sources = _read_appearance(obj, arrays)
    boxes = _boxes(obj, scene) if scene_settings.use_boxes else []
    view = None
    if scene_settings.use_view:
        if scene_settings.view_source == "CAMERA":
            view = _camera_view(obj, scene, depsgraph or bpy.context.evaluated_depsgraph_get())
        else:
            view = _viewport_view(obj, region_3d)
        view.back_ratio = scene_settings.back_ratio
        view.silhouette_angle = scene_settings.silhouette_angle
        view.silhouette_falloff = scene_settings.silhouette_falloff
        if not scene_settings.use_frustum:
            view.view_projection = None
        view.outside_probability = scene_settings.outside_probability
    view_name = "camera view" if scene_settings.view_source == "CAMERA" else "viewport view"

    def engine_guidance() -> EngineGuidance:
        out = EngineGuidance(sources=list(names), appearance=appearance, appearance_sources=list(appearance_sources))
        values = [(guidance(), strength) for guidance, strength in sources]
        if material_weights is not None:
            if any(w != 0.0 for w in material_weights):
                u = rules.material_guidance(n, arrays.triangles, arrays.triangle_material, material_weights)
                values.append((u, material_strength))
                out.sources.append("material slot weights")
            if arrays.several_materials():
                out.regions = rules.compact_regions(arrays.triangle_material)
                out.sources.append("material borders")
        out.guidance = rules.combine(values, n)
        out.borders = borders(out.sources)
        out.boxes = boxes
        if boxes:
            out.sources.append(f"{len(boxes)} box{'es' if len(boxes) > 1 else ''}")
        if view is not None:
            out.view = view
            out.sources.append(view_name)
        return out

    return engine_guidance
