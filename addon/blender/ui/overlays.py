"""Viewport overlays drawn with the ``gpu`` module: loops, generator edges, boundary and
non-manifold elements, samples and cluster regions, Hausdorff error colours and their legend.

- Nothing here runs in background mode: ``register`` adds no draw handler there, and shaders
  are created lazily on the first draw, so ``blender -b`` never touches ``gpu``.
- Everything is drawn in each object's local frame under its world matrix (object transforms
  apply), depth-tested against the scene, with a small depth bias in the projection so that
  lines and colours lying on the surface win over the surface itself.
- Batches are cached per object and rebuilt only when the object's geometry, its results or
  the overlay settings change (see ``_signature``).
- Widths are in pixels at the interface's scale (``preferences.system.pixel_size``), so HiDPI
  screens get lines as thick as others.
- A loop smaller on screen than ``marker_size`` pixels (the active loop, the clean-up preview's
  loops) also gets a ring of that size, drawn over everything: a loop of a few tenths of a
  percent of the object is a dot or nothing at the zoom that shows the whole object.
- ``unregister`` removes the draw handlers and frees every batch.
"""

from __future__ import annotations

import bpy

from . import overlay_data
from ..analysis import clean_plan
from ..preview import watch

DEPTH_BIAS = 2e-5  # in normalised device depth; pulls overlays in front of the surface they lie on
LEGEND_MARGIN, LEGEND_WIDTH, LEGEND_HEIGHT = 20, 18, 180

_handlers: dict = {}
_shaders: dict = {}
_batches: dict = {}  # object name -> (signature, [(Primitive, GPUBatch)])


def _any_shown(show) -> bool:
    return any((show.show_handles, show.show_tunnels, show.show_generators, show.show_boundary,
                show.show_nonmanifold, show.show_samples, show.show_clusters, show.show_error,
                clean_plan.any_shown()))


def pixel_scale() -> float:
    """Pixels per interface pixel (display scale and line width preference)."""
    return float(getattr(bpy.context.preferences.system, "pixel_size", 1.0) or 1.0)


def _shader(kind: str):
    """Built-in shaders by role, created on first use (never in background mode)."""
    shader = _shaders.get(kind)
    if shader is None:
        import gpu

        if kind == "POINTS":
            try:  # Blender 4.x: round points that work on every backend
                shader = gpu.shader.from_builtin("POINT_UNIFORM_COLOR")
            except (ValueError, TypeError):
                shader = gpu.shader.from_builtin("UNIFORM_COLOR")
        elif kind == "LINES":
            shader = gpu.shader.from_builtin("POLYLINE_UNIFORM_COLOR")
        else:
            shader = gpu.shader.from_builtin("SMOOTH_COLOR")
        _shaders[kind] = shader
    return shader


def _signature(obj, show, error_percent: float) -> tuple:
    topology, metrics = obj.topstoc.topology, obj.topstoc.metrics
    last = obj.topstoc.sample_sets.get("Last")
    return (watch.epoch(obj), obj.data.name_full, obj.mode, topology.state, topology.revision,
            topology.loop_index, metrics.state, metrics.revision,
            (last.parameters, last.vertices_out) if last is not None else None,
            show.show_handles, show.show_tunnels, show.show_generators, show.show_boundary,
            show.show_nonmanifold, show.show_samples, show.show_clusters, show.show_error,
            round(show.error_scale, 6), round(error_percent, 9), clean_plan.revision[0])


def _error_percent(context, show) -> float:
    """One error scale for every object shown (metrics.shared_error_percent)."""
    from ..analysis import metrics

    return metrics.shared_error_percent(context.visible_objects, show.error_scale) if show.show_error else 0.0


def _batches_of(obj, show, context, error_percent: float):
    from gpu_extras.batch import batch_for_shader

    signature = _signature(obj, show, error_percent)
    cached = _batches.get(obj.name_full)
    if cached is not None and cached[0] == signature:
        return cached[1]
    built = []
    for primitive in overlay_data.object_primitives(obj, show, context, error_percent):
        if not len(primitive):
            continue
        shader = _shader(primitive.kind)
        data = {"pos": primitive.positions}
        if primitive.colors is not None:
            data["color"] = primitive.colors
        built.append((primitive, batch_for_shader(shader, primitive.kind, data)))
    _batches[obj.name_full] = (signature, built)
    return built


def _biased_projection(projection):
    """The projection with clip-space depth pulled towards the viewer by DEPTH_BIAS."""
    biased = projection.copy()
    for column in range(4):
        biased[2][column] -= DEPTH_BIAS * biased[3][column]
    return biased


def _draw_view():
    context = bpy.context
    scene = context.scene
    if scene is None or not hasattr(scene, "topstoc"):
        return
    show = scene.topstoc.overlays
    if not _any_shown(show):
        return
    import gpu

    region = context.region
    viewport = (float(region.width), float(region.height))
    scale = pixel_scale()
    widths = {"line": scale * show.line_width, "active": scale * show.active_width, "point": scale * show.point_size}
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(False)
    gpu.state.blend_set("ALPHA")
    gpu.matrix.push_projection()
    gpu.matrix.load_projection_matrix(_biased_projection(gpu.matrix.get_projection_matrix()))
    error_percent = _error_percent(context, show)
    try:
        for obj in context.visible_objects:
            if obj.type != "MESH" or obj.data is None:
                continue
            batches = _batches_of(obj, show, context, error_percent)
            if not batches:
                continue
            with gpu.matrix.push_pop():
                gpu.matrix.multiply_matrix(obj.matrix_world)
                for primitive, batch in batches:
                    shader = _shader(primitive.kind)
                    shader.bind()
                    if primitive.kind == "LINES":
                        shader.uniform_float("viewportSize", viewport)
                        shader.uniform_float("lineWidth", widths[primitive.size])
                    elif primitive.kind == "POINTS":
                        gpu.state.point_size_set(widths[primitive.size])
                    if primitive.colors is None:
                        shader.uniform_float("color", primitive.color)
                    batch.draw(shader)
    finally:
        gpu.matrix.pop_projection()
        gpu.state.point_size_set(1.0)
        gpu.state.blend_set("NONE")
        gpu.state.depth_mask_set(True)
        gpu.state.depth_test_set("NONE")


def _draw_rings():
    """Rings around the loops too small to see at this zoom (overlay_data.small_loop_rings),
    in region pixels, over everything (no depth test in this pass)."""
    context = bpy.context
    scene = context.scene
    if scene is None or not hasattr(scene, "topstoc") or not _any_shown(scene.topstoc.overlays):
        return
    show = scene.topstoc.overlays
    region, view = context.region, context.region_data
    if view is None:
        return
    size = pixel_scale() * show.marker_size
    rings = []
    for obj in context.visible_objects:
        if obj.type == "MESH" and obj.data is not None:
            loops = overlay_data.marked_loops(obj, show)
            if loops:
                matrix = view.perspective_matrix @ obj.matrix_world
                rings += overlay_data.small_loop_rings(loops, matrix, region.width, region.height, size)
    if not rings:
        return
    import math

    from gpu_extras.batch import batch_for_shader

    shader = _shader("LINES")
    shader.bind()
    shader.uniform_float("viewportSize", (float(region.width), float(region.height)))
    shader.uniform_float("lineWidth", pixel_scale() * show.line_width)
    import gpu

    gpu.state.blend_set("ALPHA")
    steps = 32
    circle = [(math.cos(2 * math.pi * i / steps), math.sin(2 * math.pi * i / steps)) for i in range(steps + 1)]
    by_color = {}
    for x, y, radius, color in rings:  # one batch per colour
        pairs = by_color.setdefault(tuple(color), [])
        for i in range(steps):
            pairs += [(x + radius * circle[i][0], y + radius * circle[i][1], 0.0),
                      (x + radius * circle[i + 1][0], y + radius * circle[i + 1][1], 0.0)]
    for color, pairs in by_color.items():
        shader.uniform_float("color", color)
        batch_for_shader(shader, "LINES", {"pos": pairs}).draw(shader)
    gpu.state.blend_set("NONE")


def legend_object(context):
    """The object whose error scale the legend shows: the active one if it shows errors."""
    show = context.scene.topstoc.overlays
    if not show.show_error:
        return None
    candidates = [context.active_object] + list(context.visible_objects)
    for obj in candidates:
        if obj is not None and obj.type == "MESH" and obj.visible_get():
            if any(p.name == "error" for p, _ in _batches.get(obj.name_full, (None, []))[1]):
                return obj
    return None


def _draw_legend():
    context = bpy.context
    if context.scene is None or not hasattr(context.scene, "topstoc"):
        return
    obj = legend_object(context)
    if obj is None:
        return
    import blf
    import gpu
    from gpu_extras.batch import batch_for_shader

    from ...core.support import colors
    from ..analysis import metrics

    show = context.scene.topstoc.overlays
    scale = metrics.error_scale(obj, _error_percent(context, show))  # the scale every object shown uses
    x0, y0 = LEGEND_MARGIN, LEGEND_MARGIN + 30
    steps = 32
    positions, corner_colors = [], []
    ramp = colors.error_colors([scale * i / steps for i in range(steps + 1)], scale)
    for i in range(steps):
        ya, yb = y0 + LEGEND_HEIGHT * i / steps, y0 + LEGEND_HEIGHT * (i + 1) / steps
        quad = [(x0, ya, 0), (x0 + LEGEND_WIDTH, ya, 0), (x0 + LEGEND_WIDTH, yb, 0),
                (x0, ya, 0), (x0 + LEGEND_WIDTH, yb, 0), (x0, yb, 0)]
        positions += quad
        corner_colors += [tuple(ramp[i])] * 2 + [tuple(ramp[i + 1])] + [tuple(ramp[i])] + [tuple(ramp[i + 1])] * 2
    shader = _shader("TRIS")
    batch = batch_for_shader(shader, "TRIS", {"pos": positions, "color": corner_colors})
    gpu.state.blend_set("ALPHA")
    shader.bind()
    batch.draw(shader)
    gpu.state.blend_set("NONE")
    font = 0
    _font_size(blf, font, 12)
    blf.color(font, 1.0, 1.0, 1.0, 1.0)
    for t, text in colors.legend_ticks(scale, obj.topstoc.metrics.diagonal):
        blf.position(font, x0 + LEGEND_WIDTH + 6, y0 + t * LEGEND_HEIGHT - 4, 0)
        blf.draw(font, text)
    blf.position(font, x0, y0 + LEGEND_HEIGHT + 10, 0)
    blf.draw(font, f"Error per face (to the original): {obj.name}")


def _font_size(blf, font: int, size: int) -> None:
    try:
        blf.size(font, size)  # Blender 4.x
    except TypeError:
        blf.size(font, size, 72)  # Blender 3.x takes the dpi as well


def tag_redraw() -> None:
    wm = getattr(bpy.context, "window_manager", None)
    for window in getattr(wm, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def register():
    if bpy.app.background:  # no viewport to draw in, and no gpu calls allowed
        return
    space = bpy.types.SpaceView3D
    _handlers["view"] = space.draw_handler_add(_draw_view, (), "WINDOW", "POST_VIEW")
    _handlers["legend"] = space.draw_handler_add(_draw_legend, (), "WINDOW", "POST_PIXEL")
    _handlers["rings"] = space.draw_handler_add(_draw_rings, (), "WINDOW", "POST_PIXEL")
    tag_redraw()


def unregister():
    space = bpy.types.SpaceView3D
    for name in list(_handlers):
        space.draw_handler_remove(_handlers.pop(name), "WINDOW")
    _batches.clear()
    _shaders.clear()
    clean_plan.hide()
    if not bpy.app.background:
        tag_redraw()


def drawn_primitives(obj) -> list:
    """(name, kind, count) of what the last draw uploaded for ``obj`` (for tests)."""
    return [(p.name, p.kind, len(p)) for p, _ in _batches.get(obj.name_full, (None, []))[1]]
