"""The source's image-textured Principled BSDF channels (Roughness, Metallic, Emission colour,
Alpha) baked onto a result that has a UV map of its own, as the base colour is (bake_colour.py).

Each channel is baked by the emission trick: for the bake only, every source material's active
output shows the channel (its link, or its unlinked value) through an Emission shader, Cycles
bakes EMIT selected to active into a new image on the result's map, and the trick's nodes are
removed, the material's own output made active again. The result's material copies read the
channel from that image (Non-Color for the scalar ones)."""

from __future__ import annotations

from contextlib import contextmanager

import bpy

#: (file name suffix, Principled input names across Blender versions, colour data)
CHANNELS = (("roughness", ("Roughness",), False),
            ("metallic", ("Metallic",), False),
            ("emission", ("Emission Color", "Emission"), True),
            ("alpha", ("Alpha",), False))
LABELS = {f"TopStoc {kind.title()}" for kind, _, _ in CHANNELS}


def _principled(material):
    if material is None or not material.use_nodes or material.node_tree is None:
        return None
    return next((n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)


def _input(shader, names):
    return next((shader.inputs[name] for name in names if name in shader.inputs), None)


def _fed_by_image(socket) -> bool:
    """Whether an Image Texture node lies upstream of ``socket`` (through any nodes)."""
    seen, links = set(), list(socket.links)
    while links:
        node = links.pop().from_node
        if node.type == "TEX_IMAGE" and node.image is not None:
            return True
        if node.name not in seen:
            seen.add(node.name)
            links += [link for put in node.inputs for link in put.links]
    return False


def textured_channels(source) -> list:
    """The CHANNELS some material of ``source`` feeds from an image texture."""
    shaders = [_principled(slot.material) for slot in source.material_slots]
    return [channel for channel in CHANNELS
            if any(s is not None and (socket := _input(s, channel[1])) is not None and _fed_by_image(socket)
                   for s in shaders)]


def new_channel_image(name: str, size: int, colour: bool) -> bpy.types.Image:
    """A black ``size``² image to bake a channel into; Non-Color unless it is a colour."""
    image = bpy.data.images.new(name, size, size, alpha=False, float_buffer=False)
    image.generated_color = (0.0, 0.0, 0.0, 1.0)
    if not colour:
        image.colorspace_settings.name = "Non-Color"
    return image


def wire_channel(material, image, uv_map: str, names, label: str) -> None:
    """Feeds the Principled input of ``material`` named in ``names`` from ``image`` on ``uv_map`` (an
    Image Texture, made the active node: the bake writes into it); the link it replaces is removed."""
    shader = _principled(material)
    socket = _input(shader, names) if shader is not None else None
    if socket is None:
        return
    tree = material.node_tree
    offset = 300 * (list(shader.inputs).index(socket) // 4)
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image, texture.label = image, label
    texture.location = (shader.location.x - 600, shader.location.y - offset)
    coordinates = tree.nodes.new("ShaderNodeUVMap")
    coordinates.uv_map = uv_map
    coordinates.location = (shader.location.x - 800, shader.location.y - offset)
    tree.links.new(coordinates.outputs["UV"], texture.inputs["Vector"])
    for link in list(socket.links):
        tree.links.remove(link)
    tree.links.new(texture.outputs["Color"], socket)
    for node in tree.nodes:
        node.select = node is texture
    tree.nodes.active = texture


@contextmanager
def showing(materials, names):
    """While the ``with`` block runs, each material's surface is an Emission shader showing its
    Principled input named in ``names`` (its link, else its value); then the nodes added are removed
    and the material's own active output is active again."""
    added = []
    for material in {m for m in materials if _principled(m) is not None}:
        tree, shader = material.node_tree, _principled(material)
        socket = _input(shader, names)
        own = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
        emission = tree.nodes.new("ShaderNodeEmission")
        output = tree.nodes.new("ShaderNodeOutputMaterial")
        added.append((tree, own, (emission, output)))
        emission.inputs["Strength"].default_value = 1.0
        if socket is None:
            emission.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        elif socket.is_linked:
            tree.links.new(socket.links[0].from_socket, emission.inputs["Color"])
        else:
            value = socket.default_value
            emission.inputs["Color"].default_value = tuple(value) if hasattr(value, "__len__") else (value,) * 3 + (1,)
        tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
        output.is_active_output = True
    try:
        yield
    finally:
        for tree, own, nodes in added:
            for node in nodes:
                tree.nodes.remove(node)
            if own is not None:
                own.is_active_output = True


def run_emit_bake(extrusion: float, max_ray: float, margin: int, size: int) -> None:
    """Bakes the selected objects' emission into the active object's active image nodes."""
    bpy.ops.object.bake(type="EMIT", use_selected_to_active=True, use_cage=False, cage_extrusion=extrusion,
                        max_ray_distance=max_ray, margin=margin, target="IMAGE_TEXTURES", save_mode="INTERNAL",
                        use_clear=True, width=size, height=size)


def bake_channel(source, result, materials, channel, uv_map: str, reach: tuple, margin: int, size: int):
    """One CHANNEL of ``source``'s materials baked into a new image on ``uv_map`` that ``materials``
    (the result's copies) read it from; returns the image (removed again when the bake fails)."""
    kind, names, colour = channel
    image = new_channel_image(f"{result.name}_{kind}", size, colour)
    for material in materials:
        wire_channel(material, image, uv_map, names, f"TopStoc {kind.title()}")
    try:
        with showing([slot.material for slot in source.material_slots], names):
            run_emit_bake(*reach, margin, size)
    except RuntimeError:
        bpy.data.images.remove(image)
        raise
    return image
