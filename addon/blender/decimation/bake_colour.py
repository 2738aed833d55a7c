"""The source's base colour baked onto a result whose normal map has a UV map of its own
(bake.py made one: the source's layout could not hold a map). Cycles' Diffuse Color pass, selected
to active over the normal map's rays, lands on that map, and the result's material copies read
their Base Color from it: the colour the source shows at each point of the LOD, where the kept UV
map, interpolated over the LOD's large faces, would show the texture shifted."""

from __future__ import annotations

from contextlib import contextmanager

import bpy
import numpy as np

from . import bake_channels

COLOUR_LABEL = "TopStoc Base Color"


def new_colour_image(name: str, size: int) -> bpy.types.Image:
    """A black ``size``² sRGB image to bake the colour into."""
    image = bpy.data.images.new(name, size, size, alpha=False, float_buffer=False)
    image.generated_color = (0.0, 0.0, 0.0, 1.0)
    return image


def wire_colour(material, image, uv_map: str) -> None:
    """Feeds the Base Color of ``material``'s shader from ``image`` on ``uv_map`` (an Image Texture,
    made the active node: the bake writes into it); the link it replaces is removed."""
    bake_channels.wire_channel(material, image, uv_map, ("Base Color",), COLOUR_LABEL)


def run_colour_bake(extrusion: float, max_ray: float, margin: int, size: int) -> None:
    """Bakes the selected objects' diffuse colour into the active object's active image nodes."""
    sources = [obj for obj in bpy.context.selected_objects if obj != bpy.context.view_layer.objects.active]
    with without_specular(sources):
        bpy.ops.object.bake(type="DIFFUSE", pass_filter={"COLOR"}, use_selected_to_active=True, use_cage=False,
                            cage_extrusion=extrusion, max_ray_distance=max_ray, margin=margin,
                            target="IMAGE_TEXTURES", save_mode="INTERNAL", use_clear=True, width=size,
                            height=size)


@contextmanager
def without_specular(objects):
    """Sets the unlinked Specular IOR Level (Blender 4's Principled BSDF) of the ``objects``'
    materials to 0 while the ``with`` block runs, then puts it back: its layer over the diffuse one
    dims Cycles' Diffuse Color pass by its albedo (the bake came out 3.8 % darker than the base
    colour at the default IOR)."""
    saved = []
    materials = {slot.material for obj in objects for slot in obj.material_slots if slot.material is not None}
    for material in materials:
        for node in material.node_tree.nodes if material.use_nodes and material.node_tree else ():
            socket = node.inputs.get("Specular IOR Level") if node.type == "BSDF_PRINCIPLED" else None
            if socket is not None and not socket.is_linked:
                saved.append((socket, socket.default_value))
                socket.default_value = 0.0
    try:
        yield
    finally:
        for socket, value in saved:
            socket.default_value = value


def is_blank(image) -> bool:
    """Whether the image is still the black it was made with (Cycles baked nothing)."""
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return not (pixels.reshape(-1, image.channels)[:, :3] > 1e-3).any()
