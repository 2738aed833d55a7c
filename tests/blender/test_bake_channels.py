"""The source's image-textured Roughness, Metallic and Emission colour baked onto a 5 % LOD that gets a
UV map of its own (blender/decimation/bake_channels.py, with Bake Colour): a Suzanne without UV map
whose material reads them from procedural images over its generated coordinates. After Guided Decimate,
the LOD's material reads each from a baked image on its own map whose values at points of the
LOD's faces match the source's texture at the closest source points; the source's material comes
back node for node; a failed channel bake leaves nothing behind.
"""

import os

import bpy
import numpy as np
import pytest
from mathutils.bvhtree import BVHTree

from helpers import pixels_of, positions, select_only
from test_bake_colour_batch import face_samples, srgb_to_linear
from test_bake_normals import importlib_module, subdivided

TEXTURE_SIZE = 64
EMISSION = "Emission Color" if bpy.app.version >= (4, 0, 0) else "Emission"


def roughness_of(generated):
    """The roughness image's value at generated coordinates (a gradient along x)."""
    return 0.1 + 0.8 * generated[:, 0]


def metallic_of(generated):
    """The metallic image's value at generated coordinates (two waves along y)."""
    return 0.5 + 0.4 * np.sin(2 * np.pi * 2 * generated[:, 1])


def emission_of(generated):
    """The emission image's grey (linear) at generated coordinates (a product of both)."""
    return 0.2 + 0.6 * generated[:, 0] * generated[:, 1]


CHANNELS = (("Roughness", roughness_of), ("Metallic", metallic_of), (EMISSION, emission_of))


def procedural_image(name, function, data=True):
    """A TEXTURE_SIZE² float image (Non-Color with ``data``, else linear colour) holding ``function`` of its texel centres' (u, v)."""
    image = bpy.data.images.new(name, TEXTURE_SIZE, TEXTURE_SIZE, alpha=False, float_buffer=True)
    if data:
        image.colorspace_settings.name = "Non-Color"
    centres = (np.arange(TEXTURE_SIZE) + 0.5) / TEXTURE_SIZE
    v, u = np.meshgrid(centres, centres, indexing="ij")
    value = function(np.stack([u.ravel(), v.ravel()], axis=1))
    pixels = np.repeat(value[:, None], 4, axis=1)
    pixels[:, 3] = 1.0
    image.pixels.foreach_set(pixels.astype(np.float32).ravel())
    return image


def textured_suzanne():
    """Suzanne subdivided three times, smooth, without UV map; its Principled BSDF's Roughness,
    Metallic and Emission colour read from procedural images over the generated coordinates."""
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
    for name, function in CHANNELS:
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image, node.extension = procedural_image(name.split()[0].lower(), function, name != EMISSION), "EXTEND"
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
    pixels = pixels_of(image)
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


def test_guided_decimate_bakes_the_textured_channels(ts, scene):
    source = textured_suzanne()
    material = source.material_slots[0].material
    before = tree_snapshot(material)
    lod = decimate_with_channels(source)
    assert tree_snapshot(material) == before                     # the emission trick left no trace
    assert len(lod.data.polygons) < len(source.data.polygons) / 10
    lod_material = lod.material_slots[0].material
    assert lod_material is not material
    for name, function in CHANNELS:
        wired = input_image(lod_material, name)
        assert wired is not None, f"the LOD's {name} reads no baked image"
        node, uv_map = wired
        data = name != EMISSION
        assert (node.image.colorspace_settings.name == "Non-Color") == data and tuple(node.image.size) == (256, 256)
        assert node.image.packed_file is not None and node.image.name == f"{lod.name}_{name.split()[0].lower()}"
        points, uvs, _, _ = face_samples(lod.data, uv_map)
        baked = sample(node.image, uvs) if data else srgb_to_linear(sample(node.image, uvs))
        expected = function(generated(source.data, closest_source_points(source, points)))
        error = np.abs(baked - expected)
        print(f"{name}: baked range {baked.min():.3f}..{baked.max():.3f}, mean error {error.mean():.4f}, "
              f"95th percentile {np.percentile(error, 95):.4f}, over 0.1 {(error > 0.1).mean():.4f} of {len(error)}")
        assert np.ptp(baked) > 0.5                                # the texture, not a flat value
        assert error.mean() < 0.015  # the measured figures: docs/blender-addon.md, Bake Colour
        assert np.percentile(error, 95) < 0.03


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
    assert [kind for kind, _, _ in channels.textured_channels(source)] == ["roughness", "metallic", "emission"]
    shader = next(n for n in source.material_slots[0].material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    tree = source.material_slots[0].material.node_tree
    tree.links.remove(shader.inputs["Metallic"].links[0])
    assert [kind for kind, _, _ in channels.textured_channels(source)] == ["roughness", "emission"]


def test_batch_writes_the_channels_beside_a_gltf(ts, scene, tmp_path):
    """``--bake-colour`` in the batch: the roughness and metallic PNGs next to the output as
    ``<stem>_<object>_<channel>.png`` (Non-Color values within the texture's range), and the glTF's
    material gets a metallicRoughnessTexture Blender's exporter combines from them."""
    import json
    import subprocess

    from test_batch_formats import _runner

    source = textured_suzanne()
    for node in source.material_slots[0].material.node_tree.nodes:
        if node.type == "TEX_IMAGE":
            node.image.pack()  # the batch's Blender reads the source's textures from the .blend
    blend = tmp_path / "textured.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    out, report = tmp_path / "out", tmp_path / "report.json"
    command = importlib_module(ts, "core.batch.run").blender_command(_runner()) + [
        "--input", str(blend), "--output", str(out), "--json", str(report), "--ratio", "0.05",
        "--format", "gltf", "--bake-normals", "256", "--bake-colour"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    if done.returncode and "Cycles baked no colour" in done.stderr:
        pytest.skip(f"Blender {bpy.app.version_string}'s Cycles bakes no colour selected-to-active")
    assert done.returncode == 0, done.stderr[-2000:]
    [lod] = json.loads(report.read_text())["results"][0]["objects"][0]["lods"]
    for kind, function in (("roughness", roughness_of), ("metallic", metallic_of)):
        assert lod[f"{kind}_map"] == str(out / f"textured_textured_{kind}.png")
        written = bpy.data.images.load(lod[f"{kind}_map"])
        written.colorspace_settings.name = "Non-Color"
        pixels = pixels_of(written)
        values = pixels.reshape(-1, written.channels)[:, 0]
        expected = function(generated(source.data, positions(source.data).astype(np.float64)))
        covered = values[values > 0.01]  # texels the bake reached (the rest stays black)
        low, high = np.percentile(covered, [1, 99])  # the island edges' texels blend in the black
        print(f"{kind}: texels' 1st-99th percentiles {low:.3f}..{high:.3f}, the texture's range "
              f"{expected.min():.3f}..{expected.max():.3f}")
        assert expected.min() - 0.02 < low < expected.min() + 0.1 and expected.max() - 0.1 < high < expected.max() + 0.02
        assert np.ptp(covered) > 0.6
    assert not [name for name in os.listdir(out) if name.startswith(".topstoc-")]
    gltf = json.loads((out / "textured.gltf").read_text())
    [material] = gltf["materials"]
    print("glTF material:", json.dumps(material), "images:", [i.get("uri") for i in gltf.get("images", [])])
    reference = material["pbrMetallicRoughness"]["metallicRoughnessTexture"]
    uri = gltf["images"][gltf["textures"][reference["index"]]["source"]]["uri"]
    combined = bpy.data.images.load(str(out / uri))  # Blender's exporter packs G = roughness, B = metallic
    combined.colorspace_settings.name = "Non-Color"
    for channel, kind in ((1, "roughness"), (2, "metallic")):
        single = bpy.data.images.load(lod[f"{kind}_map"], check_existing=True)
        single.colorspace_settings.name = "Non-Color"
        a, b = pixels_of(combined), pixels_of(single)
        assert np.abs(a.reshape(-1, combined.channels)[:, channel] - b.reshape(-1, single.channels)[:, 0]).max() < 1 / 255


def test_cancel_and_removal_take_the_channel_maps_too(ts, scene, monkeypatch):
    """Cancelled between two channels (Esc), the bake leaves the LOD, the images and the source's
    material as they were; a finished bake's result removed (a cancelled multi-object run) takes
    its channel images with it."""
    from test_bake_normals import decimated

    bake = importlib_module(ts, "blender.decimation.bake")
    raycast = importlib_module(ts, "blender.decimation.bake_raycast")
    source = textured_suzanne()
    lod = decimated(ts, source, "lod")
    material = source.material_slots[0].material
    monkeypatch.setattr(bake.bake_colour, "is_blank", lambda image: False)  # Cycles 3.4 bakes no colour
    before = ([slot.material for slot in lod.material_slots], [layer.name for layer in lod.data.uv_layers],
              set(bpy.data.images), {m.name for m in bpy.data.materials}, tree_snapshot(material))
    baked = []
    real = bake.bake_channels.run_emit_bake
    monkeypatch.setattr(bake.bake_channels, "run_emit_bake", lambda *args: (baked.append(1), real(*args)))
    with pytest.raises(raycast.Cancelled):
        bake.bake_normals(bpy.context, source, lod, size=64, margin=2, colour=True,
                          progress=lambda fraction: len(baked) < 2)
    assert len(baked) == 2                                        # roughness and metallic were baked
    assert ([slot.material for slot in lod.material_slots], [layer.name for layer in lod.data.uv_layers],
            set(bpy.data.images), {m.name for m in bpy.data.materials}, tree_snapshot(material)) == before
    result = bake.bake_normals(bpy.context, source, lod, size=64, margin=2, colour=True)
    assert sorted(result.channels) == ["emission", "metallic", "roughness"]
    assert {image.name for image in bpy.data.images} - {image.name for image in before[2]} == {
        "lod_normal", "lod_color", "lod_roughness", "lod_metallic", "lod_emission"}
    bake.remove_results([lod])
    assert set(bpy.data.images) == before[2] and tree_snapshot(material) == before[-1]
