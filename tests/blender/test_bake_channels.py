"""The source's image-textured Roughness and Metallic baked onto a 5 % LOD that gets a UV map of its
own (blender/decimation/bake_channels.py, with Bake Colour): a Suzanne without UV map whose
material reads both from procedural images over its generated coordinates. After Guided Decimate,
the LOD's material reads each from a baked image on its own map whose values at points of the
LOD's faces match the source's texture at the closest source points; the source's material comes
back node for node; a failed channel bake leaves nothing behind.
"""

import bpy
import numpy as np
import pytest
from mathutils.bvhtree import BVHTree

from helpers import positions, select_only
from test_bake_colour_batch import face_samples
from test_bake_normals import importlib_module, subdivided

TEXTURE_SIZE = 64


def roughness_of(generated):
    """The roughness image's value at generated coordinates (a gradient along x)."""
    return 0.1 + 0.8 * generated[:, 0]


def metallic_of(generated):
    """The metallic image's value at generated coordinates (two waves along y)."""
    return 0.5 + 0.4 * np.sin(2 * np.pi * 2 * generated[:, 1])


def procedural_image(name, function):
    """A TEXTURE_SIZE² Non-Color float image holding ``function`` of its texel centres' (u, v)."""
    image = bpy.data.images.new(name, TEXTURE_SIZE, TEXTURE_SIZE, alpha=False, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    centres = (np.arange(TEXTURE_SIZE) + 0.5) / TEXTURE_SIZE
    v, u = np.meshgrid(centres, centres, indexing="ij")
    value = function(np.stack([u.ravel(), v.ravel()], axis=1))
    pixels = np.repeat(value[:, None], 4, axis=1)
    pixels[:, 3] = 1.0
    image.pixels.foreach_set(pixels.astype(np.float32).ravel())
    return image


def textured_suzanne():
    """Suzanne subdivided three times, smooth, without UV map; its Principled BSDF's Roughness and
    Metallic read from procedural images over the generated coordinates."""
    bpy.ops.mesh.primitive_monkey_add()
    monkey = subdivided(bpy.context.active_object, 3)
    monkey.name = "textured"
    while monkey.data.uv_layers:
        monkey.data.uv_layers.remove(monkey.data.uv_layers[0])
    for polygon in monkey.data.polygons:
        polygon.use_smooth = True
    material = bpy.data.materials.new("textured")
    material.use_nodes = True
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    for name, function in (("Roughness", roughness_of), ("Metallic", metallic_of)):
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image, node.extension = procedural_image(name.lower(), function), "EXTEND"
        tree.links.new(coordinates.outputs["Generated"], node.inputs["Vector"])
        tree.links.new(node.outputs["Color"], shader.inputs[name])
    monkey.data.materials.append(material)
    return monkey


def generated(mesh, points):
    """The mesh's generated texture coordinates at local ``points`` (its texture space)."""
    location, size = np.array(mesh.texspace_location), np.array(mesh.texspace_size)
    return (points - location) / size * 0.5 + 0.5


def tree_snapshot(material):
    """Everything a test needs to prove a node tree unchanged."""
    def value(socket):
        v = getattr(socket, "default_value", None)
        return tuple(v) if hasattr(v, "__len__") and not isinstance(v, str) else v
    tree = material.node_tree
    nodes = sorted((n.name, n.type, tuple(n.location), getattr(n, "is_active_output", None),
                    tuple((s.identifier, value(s)) for s in n.inputs)) for n in tree.nodes)
    links = [(l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier)
             for l in tree.links]
    return nodes, links, tree.nodes.active.name if tree.nodes.active else None


def input_image(material, name):
    """(image node, its UV map) feeding ``material``'s Principled input ``name`` directly, or None."""
    shader = next(n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    links = shader.inputs[name].links
    if not links or links[0].from_node.type != "TEX_IMAGE":
        return None
    node = links[0].from_node
    coordinates = node.inputs["Vector"].links[0].from_node if node.inputs["Vector"].links else None
    return (node, coordinates.uv_map) if coordinates is not None and coordinates.type == "UVMAP" else None


def sample(image, uvs):
    """The image's first channel at ``uvs`` (bilinear over texel centres; Non-Color: stored values)."""
    width, height = image.size
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    grid = pixels.reshape(height, width, -1)[..., 0].astype(np.float64)
    x = np.clip(uvs[:, 0] * width - 0.5, 0, width - 1)
    y = np.clip(uvs[:, 1] * height - 0.5, 0, height - 1)
    x0, y0 = np.minimum(x.astype(int), width - 2), np.minimum(y.astype(int), height - 2)
    fx, fy = x - x0, y - y0
    return (grid[y0, x0] * (1 - fx) * (1 - fy) + grid[y0, x0 + 1] * fx * (1 - fy)
            + grid[y0 + 1, x0] * (1 - fx) * fy + grid[y0 + 1, x0 + 1] * fx * fy)


def closest_source_points(source, points):
    """The closest points of ``source``'s surface to ``points`` (both local: the LOD is made in place)."""
    mesh = source.data
    tree = BVHTree.FromPolygons(positions(mesh).astype(np.float64).tolist(), [p.vertices[:] for p in mesh.polygons])
    return np.array([tree.find_nearest(point)[0] for point in points])


def decimate_with_channels(source):
    select_only(source)
    try:
        bpy.ops.topstoc.guided_decimate(ratio=0.05, bake_normals=True, bake_size="256", bake_margin=4,
                                        bake_colour=True)
    except RuntimeError as error:
        if "Cycles baked no colour" in str(error):
            pytest.skip(f"Blender {bpy.app.version_string}'s Cycles bakes no colour selected-to-active "
                        f"(the channel bakes have no ray-cast fallback)")
        raise
    [lod] = [o for o in bpy.context.scene.objects if o.type == "MESH" and o is not source]
    return lod


def test_guided_decimate_bakes_roughness_and_metallic(ts, scene):
    source = textured_suzanne()
    material = source.material_slots[0].material
    before = tree_snapshot(material)
    lod = decimate_with_channels(source)
    assert tree_snapshot(material) == before                     # the emission trick left no trace
    assert len(lod.data.polygons) < len(source.data.polygons) / 10
    lod_material = lod.material_slots[0].material
    assert lod_material is not material
    for name, function in (("Roughness", roughness_of), ("Metallic", metallic_of)):
        wired = input_image(lod_material, name)
        assert wired is not None, f"the LOD's {name} reads no baked image"
        node, uv_map = wired
        assert node.image.colorspace_settings.name == "Non-Color" and tuple(node.image.size) == (256, 256)
        assert node.image.packed_file is not None and node.image.name == f"{lod.name}_{name.lower()}"
        points, uvs, _, _ = face_samples(lod.data, uv_map)
        baked = sample(node.image, uvs)
        expected = function(generated(source.data, closest_source_points(source, points)))
        error = np.abs(baked - expected)
        print(f"{name}: baked range {baked.min():.3f}..{baked.max():.3f}, mean error {error.mean():.4f}, "
              f"95th percentile {np.percentile(error, 95):.4f}, over 0.1 {(error > 0.1).mean():.4f} of {len(error)}")
        assert np.ptp(baked) > 0.6                                # the texture, not a flat value
        assert error.mean() < 0.015                               # measured 0.0022, 0.0054 (bpy 4.5)
        assert np.percentile(error, 95) < 0.03                    # measured 0.0016, 0.0088 (bpy 4.5)


def test_a_failed_channel_bake_leaves_nothing(ts, scene, monkeypatch):
    """A channel bake that fails: a one-line error; the LOD's materials and UV maps, the images and
    the source's material are as before (the normal and colour maps it made are removed too)."""
    from test_bake_normals import decimated

    bake = importlib_module(ts, "blender.decimation.bake")
    source = textured_suzanne()
    lod = decimated(ts, source, "lod")
    material = source.material_slots[0].material
    before = ([slot.material for slot in lod.material_slots], [layer.name for layer in lod.data.uv_layers],
              set(bpy.data.images), {m.name for m in bpy.data.materials}, tree_snapshot(material))
    monkeypatch.setattr(bake.bake_colour, "is_blank", lambda image: False)  # a colour bake that "worked"
    monkeypatch.setattr(bake.bake_colour, "run_colour_bake", lambda *args: None)
    calls = []

    def fail_second(*args):
        calls.append(tree_snapshot(material))
        if len(calls) == 2:
            raise RuntimeError("Error: out of memory")
    monkeypatch.setattr(bake.bake_channels, "run_emit_bake", fail_second)
    with pytest.raises(bake.BakeError, match="^baking the metallic onto 'lod' failed: Error: out of memory$"):
        bake.bake_normals(bpy.context, source, lod, size=64, margin=2, colour=True)
    assert calls[0] != before[-1]                              # the trick was in place while baking
    assert ([slot.material for slot in lod.material_slots], [layer.name for layer in lod.data.uv_layers],
            set(bpy.data.images), {m.name for m in bpy.data.materials}, tree_snapshot(material)) == before


def test_only_image_textured_channels_are_baked(ts, scene):
    channels = importlib_module(ts, "blender.decimation.bake_channels")
    source = textured_suzanne()
    assert [kind for kind, _, _ in channels.textured_channels(source)] == ["roughness", "metallic"]
    shader = next(n for n in source.material_slots[0].material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    tree = source.material_slots[0].material.node_tree
    tree.links.remove(shader.inputs["Metallic"].links[0])
    assert [kind for kind, _, _ in channels.textured_channels(source)] == ["roughness"]
