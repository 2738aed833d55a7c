"""``--bake-colour`` in the batch (blender/batch.py): a vertex-painted source without a UV map is
decimated to 2 % and written as glTF; the LOD gets a UV map of its own, its normal map and its base
colour baked onto it, both PNGs next to the output, and the glTF's material names the colour as its
baseColorTexture. Re-imported, the texture read at points of the LOD's faces shows the source's
colours there (within a tolerance, and much closer than the LOD's vertices' colours blended over
its faces, which is all a 2 % LOD without the texture can show).
"""

import json
import os
import subprocess

import bpy
import numpy as np
import pytest
from mathutils.kdtree import KDTree

from helpers import pixels_of, positions, reimported
from test_bake_normals import importlib_module, painted_suzanne

SAMPLES_PER_FACE = 8


def source_colours(obj):
    """(KD-tree of the source's vertices, their linear RGB colours from the 'paint' attribute)."""
    mesh = obj.data
    colours = np.empty(4 * len(mesh.vertices), dtype=np.float32)
    mesh.color_attributes["paint"].data.foreach_get("color", colours)
    co = positions(mesh).astype(np.float64)
    tree = KDTree(len(co))
    for index, point in enumerate(co):
        tree.insert(point, index)
    tree.balance()
    return tree, colours.reshape(-1, 4)[:, :3]


def colour_at(tree, colours, points):
    return np.array([colours[tree.find(point)[1]] for point in points])


def base_colour_image(obj):
    """The image feeding the Base Color of the object's first material's Principled BSDF (through
    whatever nodes the importer puts between), or None."""
    tree = obj.material_slots[0].material.node_tree
    shader = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    links = list(shader.inputs["Base Color"].links)
    while links:
        node = links[0].from_node
        if node.type == "TEX_IMAGE":
            return node
        links = [link for socket in node.inputs for link in socket.links]
    return None


def srgb_to_linear(values):
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def face_samples(mesh, uv_name: str, seed: int = 0):
    """Points inside every triangle of ``mesh`` (random barycentric weights, fixed seed): their
    positions, UVs on ``uv_name`` and the weights, with the triangles' vertex indices."""
    mesh.calc_loop_triangles()
    loops = np.array([tri.loops[:] for tri in mesh.loop_triangles])
    vertices = np.array([tri.vertices[:] for tri in mesh.loop_triangles])
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    mesh.uv_layers[uv_name].data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    co = positions(mesh).astype(np.float64)
    weights = np.random.default_rng(seed).dirichlet(np.ones(3), size=(len(loops), SAMPLES_PER_FACE))
    points = np.einsum("fsk,fkd->fsd", weights, co[vertices]).reshape(-1, 3)
    uvs = np.einsum("fsk,fkd->fsd", weights, uv[loops]).reshape(-1, 2)
    return points, uvs, weights, vertices


def texels(image, uvs):
    """The image's linear RGB at ``uvs`` (nearest texel; the PNG holds sRGB)."""
    width, height = image.size
    pixels = pixels_of(image)
    pixels = pixels.reshape(height, width, -1)[..., :3]
    x = np.clip((uvs[:, 0] * width).astype(int), 0, width - 1)
    y = np.clip((uvs[:, 1] * height).astype(int), 0, height - 1)
    return srgb_to_linear(pixels[y, x].astype(np.float64))


def batch_bake_colour(ts, tmp_path, out_format: str):
    """Runs the batch on the scene saved as ``painted.blend`` with ``--ratio 0.02 --bake-normals 256
    --bake-colour --format out_format`` (skipped where Cycles bakes no colour); returns (output
    folder, the LOD's report entry)."""
    from test_batch_formats import _runner

    blend = tmp_path / "painted.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    out, report = tmp_path / "out", tmp_path / "report.json"
    command = importlib_module(ts, "core.batch.run").blender_command(_runner()) + [
        "--input", str(blend), "--output", str(out), "--json", str(report), "--ratio", "0.02",
        "--format", out_format, "--bake-normals", "256", "--bake-colour"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    if done.returncode and "Cycles baked no colour" in done.stderr:
        pytest.skip(f"Blender {bpy.app.version_string}'s Cycles bakes no colour selected-to-active "
                    f"(the colour bake has no ray-cast fallback)")
    assert done.returncode == 0, done.stderr[-2000:]
    [lod] = json.loads(report.read_text())["results"][0]["objects"][0]["lods"]
    return out, lod


def test_batch_bakes_the_base_colour_into_a_gltf(ts, scene, tmp_path):
    source = painted_suzanne()
    tree, colours = source_colours(source)
    source_faces = len(source.data.polygons)
    out, lod = batch_bake_colour(ts, tmp_path, "gltf")
    assert lod["colour_map"] == str(out / "painted_painted_color.png")
    assert lod["normal_map"] == str(out / "painted_painted_normal.png")
    assert lod["dropped_colour_attributes"] == ["paint"]  # its colours are in the texture now
    assert sorted(os.listdir(out)) == ["painted.bin", "painted.gltf", "painted_painted_color.png",
                                       "painted_painted_normal.png"]
    gltf = json.loads((out / "painted.gltf").read_text())
    [material] = gltf["materials"]
    uri = lambda ref: gltf["images"][gltf["textures"][ref["index"]]["source"]]["uri"]  # noqa: E731
    assert uri(material["pbrMetallicRoughness"]["baseColorTexture"]) == "painted_painted_color.png"
    assert uri(material["normalTexture"]) == "painted_painted_normal.png"
    # glTF multiplies the base colour by COLOR_0: the vertex colours no material reads must stay out
    assert all("COLOR_0" not in p["attributes"] for mesh in gltf["meshes"] for p in mesh["primitives"])

    obj = reimported(ts, out / "painted.gltf")
    assert len(obj.data.polygons) == lod["triangles"] < source_faces / 20
    node = base_colour_image(obj)
    assert node is not None and tuple(node.image.size) == (256, 256)
    uv_name = node.inputs["Vector"].links[0].from_node.uv_map if node.inputs["Vector"].links else \
        obj.data.uv_layers.active.name
    points, uvs, weights, vertices = face_samples(obj.data, uv_name)
    baked = texels(node.image, uvs)
    assert np.ptp(baked, axis=0).min() > 0.3                     # the stripes, not a blank image
    expected = colour_at(tree, colours, points)
    at_vertices = colour_at(tree, colours, positions(obj.data).astype(np.float64))
    blended = np.einsum("fsk,fkc->fsc", weights, at_vertices[vertices]).reshape(-1, 3)
    baked_error = np.abs(baked - expected).mean(axis=1)
    blended_error = np.abs(blended - expected).mean(axis=1)
    print(f"painted Suzanne, batch glTF: mean colour error of the baked texture {baked_error.mean():.4f} "
          f"(median {np.median(baked_error):.4f}), of the LOD's vertex colours {blended_error.mean():.4f}")
    bias = (baked - expected).mean(axis=0)
    print(f"  mean signed difference per channel {np.round(bias, 4)}")
    assert np.abs(bias).max() < 0.005        # not darker: the specular layer is off during the bake
    assert baked_error.mean() < 0.03         # figures: docs/pipelines.md, Colour maps
    assert baked_error.mean() < 0.6 * blended_error.mean()


def test_batch_embeds_the_base_colour_in_an_fbx(ts, scene, tmp_path):
    """The FBX output carries the baked colour (embedded, as the normal map): moved elsewhere without
    the PNGs, it re-imports with the colour PNG's pixels feeding the Base Color. FBX has no rule
    multiplying vertex colours in: the LOD keeps its colour attribute."""
    import shutil

    painted_suzanne()
    out, lod = batch_bake_colour(ts, tmp_path, "fbx")
    assert "dropped_colour_attributes" not in lod
    written = bpy.data.images.load(lod["colour_map"])
    expected = pixels_of(written)
    moved = tmp_path / "moved"
    shutil.move(str(out), str(moved))
    for name in os.listdir(moved):
        if name.endswith(".png"):
            os.remove(moved / name)
    obj = reimported(ts, moved / "painted.fbx")
    node = base_colour_image(obj)
    assert node is not None and tuple(node.image.size) == (256, 256)
    pixels = pixels_of(node.image)
    assert np.array_equal(pixels, expected) and np.ptp(expected) > 0.3
    assert "paint" in obj.data.color_attributes


def test_batch_connects_the_base_colour_in_a_usd(ts, scene, tmp_path):
    """USD output: the UsdPreviewSurface's diffuseColor reads the colour PNG (the exporter copies it
    to textures/), and Blender's importer reads it back into the Base Color. Debian's Blender 3.4
    is built without USD."""
    if not bpy.app.build_options.usd:
        pytest.skip(f"Blender {bpy.app.version_string} is built without USD")
    painted_suzanne()
    out, lod = batch_bake_colour(ts, tmp_path, "usda")
    name = os.path.basename(lod["colour_map"])
    text = (out / "painted.usda").read_text()
    assert "color3f inputs:diffuseColor.connect = </root/_materials/" in text
    assert f"asset inputs:file = @./textures/{name}@" in text
    assert name in os.listdir(out / "textures")
    obj = reimported(ts, out / "painted.usda", images=True)
    node = base_colour_image(obj)
    assert node is not None and tuple(node.image.size) == (256, 256)
    written = bpy.data.images.load(lod["colour_map"])
    imported, expected = pixels_of(node.image), pixels_of(written)
    assert np.array_equal(imported, expected) and np.ptp(expected) > 0.3


def test_the_colour_bake_leaves_the_source_material_as_it_was(ts, scene):
    """The colour bake turns the source's specular layer off while it runs (it dims the Diffuse
    Color pass) and puts it back."""
    from test_bake_normals import decimated

    bake = importlib_module(ts, "blender.decimation.bake")
    source = painted_suzanne()
    shader = next(n for n in source.material_slots[0].material.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    socket = shader.inputs.get("Specular IOR Level")
    if socket is None:
        pytest.skip(f"Blender {bpy.app.version_string}'s Principled BSDF has no specular layer over the diffuse")
    socket.default_value = 0.7
    seen = []
    with bake.bake_colour.without_specular([source]):
        seen.append(socket.default_value)
    assert seen == [0.0] and socket.default_value == pytest.approx(0.7)
    lod = decimated(ts, source, "lod")
    try:
        bake.bake_normals(bpy.context, source, lod, size=64, margin=2, colour=True)
    except bake.BakeError as error:  # Cycles that bakes no colour: the material must still come back
        assert "baked no colour" in str(error)
    assert socket.default_value == pytest.approx(0.7)
