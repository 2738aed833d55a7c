"""Renders for the shading tests: one object at a time under a fixed sun and orthographic camera
(Cycles, direct light only, so the picture is the surface's shading and nothing else), read back
as numpy arrays; and a side-by-side picture of several objects with captions."""

import math
import os

import bpy
import numpy as np
from mathutils import Vector

SUN_DIRECTION = (math.radians(50), 0.0, math.radians(-35))  #: the sun's rotation (from the upper left front)


def setup(size: int = 256, engine: str = "CYCLES") -> None:
    """Cycles on the CPU, direct light only (or EEVEE: ``engine="EEVEE"``, the viewport's material
    look), no cast shadows, black world, transparent film, Standard view."""
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 8
    scene.cycles.max_bounces = 0
    scene.cycles.use_denoising = False
    scene.cycles.seed = 0
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    world = bpy.data.worlds.new("black")
    world.color = (0.0, 0.0, 0.0)
    world.use_nodes = False
    scene.world = world
    sun_data = bpy.data.lights.new("sun", "SUN")
    sun_data.energy = 3.0
    sun_data.angle = 0.0
    if hasattr(sun_data, "use_shadow"):  # no cast shadows: the picture is N.L, what a normal map changes
        sun_data.use_shadow = False
    if hasattr(getattr(sun_data, "cycles", None), "cast_shadow"):
        sun_data.cycles.cast_shadow = False
    if engine == "EEVEE":
        for name in ("BLENDER_EEVEE_NEXT", "BLENDER_EEVEE"):  # 4.2-4.5 call it EEVEE Next
            try:
                scene.render.engine = name
                break
            except TypeError:
                continue
        scene.eevee.taa_render_samples = 8
    sun = bpy.data.objects.new("sun", sun_data)
    sun.rotation_euler = SUN_DIRECTION
    scene.collection.objects.link(sun)


def frame(objects, margin: float = 1.08, aspect: float = 1.0) -> None:
    """An orthographic camera looking along +Y at the world bounding box of ``objects``."""
    corners = np.array([tuple(obj.matrix_world @ Vector(c)) for obj in objects for c in obj.bound_box])
    low, high = corners.min(axis=0), corners.max(axis=0)
    centre = (low + high) / 2
    data = bpy.data.cameras.new("camera")
    data.type = "ORTHO"
    data.ortho_scale = margin * max(high[0] - low[0], (high[2] - low[2]) * aspect)
    camera = bpy.data.objects.new("camera", data)
    camera.location = (centre[0], low[1] - 10.0, centre[2])
    camera.rotation_euler = (math.radians(90), 0.0, 0.0)
    data.clip_end = 100.0
    bpy.context.scene.collection.objects.link(camera)
    bpy.context.scene.camera = camera


def render(obj, folder: str, name: str) -> np.ndarray:
    """RGBA float array (rows top down) of ``obj`` alone."""
    scene = bpy.context.scene
    shown = {o: o.hide_render for o in scene.objects}
    for other in scene.objects:
        if other.type in ("MESH", "FONT"):
            other.hide_render = other is not obj
    try:
        return render_scene(folder, name)
    finally:
        for other, hidden in shown.items():
            other.hide_render = hidden


def render_scene(folder: str, name: str) -> np.ndarray:
    """Renders the scene to ``<folder>/<name>.png``; its RGBA floats (rows top down)."""
    scene = bpy.context.scene
    path = os.path.join(folder, name + ".png")
    scene.render.filepath = path
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    width, height = image.size
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1]


def shading_difference(reference: np.ndarray, other: np.ndarray, mask: np.ndarray) -> float:
    """Mean absolute difference of the shading (grey level) over the pixels of ``mask``."""
    grey = lambda rgba: rgba[..., :3].mean(axis=-1)  # noqa: E731
    return float(np.abs(grey(reference) - grey(other))[mask].mean())


def covered(*images, inset: int = 4) -> np.ndarray:
    """The pixels every image covers fully, ``inset`` pixels inside every silhouette (the edge
    pixels mix surface and background: no shading to compare)."""
    mask = np.logical_and.reduce([image[..., 3] > 0.999 for image in images])
    for _ in range(inset):
        inner = mask.copy()
        inner[1:] &= mask[:-1]
        inner[:-1] &= mask[1:]
        inner[:, 1:] &= mask[:, :-1]
        inner[:, :-1] &= mask[:, 1:]
        mask = inner
    return mask


def _caption_material():
    material = bpy.data.materials.get("caption") or bpy.data.materials.new("caption")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    output = nodes.new("ShaderNodeOutputMaterial")
    material.node_tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    return material


def _write_over_background(pixels: np.ndarray, path: str, grey: float = 0.22) -> None:
    """Rewrites the render at ``path`` opaque, over a grey background (legible on light and dark pages)."""
    alpha = pixels[..., 3:4]
    rgb = pixels[..., :3] * alpha + grey * (1.0 - alpha)  # PNG colours are straight, not premultiplied
    height, width = rgb.shape[:2]
    image = bpy.data.images.new("side_by_side", width, height, alpha=False)
    image.pixels.foreach_set(np.concatenate([rgb, np.ones_like(alpha)], axis=-1)[::-1].ravel())
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def side_by_side(objects, captions, path: str, width: int = 768) -> None:
    """One render of ``objects`` in a row (moved apart for the picture, then put back) with a caption
    under each, written as PNG to ``path``."""
    scene = bpy.context.scene
    placed = [obj.matrix_world.copy() for obj in objects]
    span = max(obj.dimensions.x for obj in objects) * 1.15
    texts = []
    for index, (obj, caption) in enumerate(zip(objects, captions)):
        obj.location.x += index * span
        text = bpy.data.curves.new(f"caption{index}", "FONT")
        text.body = caption
        text.align_x = "CENTER"
        text.size = 0.075 * span
        text.materials.append(_caption_material())
        label = bpy.data.objects.new(f"caption{index}", text)
        label.rotation_euler = (math.radians(90), 0.0, 0.0)
        bpy.context.view_layer.update()
        low_z = min((obj.matrix_world @ Vector(c)).z for c in obj.bound_box)
        label.location = (obj.matrix_world.translation.x, -5.0, low_z - 0.14 * span)
        scene.collection.objects.link(label)
        texts.append(label)
    bpy.context.view_layer.update()
    old = scene.render.resolution_x, scene.render.resolution_y, scene.camera
    scene.render.resolution_x, scene.render.resolution_y = width, width * 2 // 5
    frame(list(objects) + texts, margin=1.02, aspect=2.5)
    hidden = {o: o.hide_render for o in scene.objects}
    for other in scene.objects:
        other.hide_render = other.type in ("MESH", "FONT") and other not in objects and other not in texts
    try:
        folder, name = os.path.split(path)
        pixels = render_scene(folder, os.path.splitext(name)[0])
        _write_over_background(pixels, path)
    finally:
        for other, flag in hidden.items():
            other.hide_render = flag
        scene.render.resolution_x, scene.render.resolution_y, scene.camera = old
        for obj, matrix in zip(objects, placed):
            obj.matrix_world = matrix
        for label in texts:
            bpy.data.objects.remove(label)
