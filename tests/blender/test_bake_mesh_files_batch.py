"""``--bake-normals`` on mesh files in the batch (blender/batch.py): an OBJ (a subdivided Suzanne) is
imported by Blender, decimated, baked and written as OBJ whose .mtl names the normal map (map_Bump), a
PNG next to it; re-imported, the material's Normal Map node holds that PNG's pixels. Written as glTF,
the material names it as normalTexture. An OFF file (no Blender importer) goes through the project's
reader. Outputs that have no material (PLY, STL) are refused with the way out.
"""

import json
import os
import subprocess

import bpy
import numpy as np
import pytest

from helpers import pixels_of, reimported
from test_bake_normals import importlib_module, normal_map_image

SIZE = 128


def subdivided_suzanne(path) -> int:
    """Writes a Suzanne subdivided twice (smooth, 7.9k faces, no UV map kept) as OBJ; its face count."""
    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.active_object
    obj.name = "Suzanne"
    modifier = obj.modifiers.new("subdivide", "SUBSURF")
    modifier.levels = 2
    bpy.ops.object.modifier_apply(modifier=modifier.name)
    for layer in list(obj.data.uv_layers):
        obj.data.uv_layers.remove(layer)
    export = bpy.ops.wm.obj_export
    names = {p.identifier for p in export.get_rna_type().properties}
    options = {"export_materials": False, "export_selected_objects": True, "export_uv": False}
    export(filepath=str(path), **{k: v for k, v in options.items() if k in names})
    return len(obj.data.polygons)


def run_batch(ts, source, out, *argv):
    """The Blender batch on ``source`` with ``--ratio 0.05 --bake-normals SIZE`` and ``argv``:
    (the completed process, the report's entry or None)."""
    from test_batch_formats import _runner

    report = out.parent / "report.json"
    command = importlib_module(ts, "core.batch.run").blender_command(_runner()) + [
        "--input", str(source), "--output", str(out), "--json", str(report), "--ratio", "0.05",
        "--bake-normals", str(SIZE), *map(str, argv)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    results = json.loads(report.read_text())["results"] if report.exists() else []
    return done, (results[0] if results else None)


def mtl_maps(path) -> dict:
    """The .mtl's map statements: {"map_Bump": file name, ...} (options such as -bm 1 left out)."""
    maps = {}
    for line in path.read_text().splitlines():
        words = line.split()
        if words and words[0].startswith(("map_", "norm", "bump")):
            maps[words[0]] = words[-1]
    return maps


def test_an_obj_is_baked_into_an_obj_whose_mtl_names_the_map(ts, scene, tmp_path):
    source_faces = subdivided_suzanne(tmp_path / "suzanne.obj")
    out = tmp_path / "out"
    done, entry = run_batch(ts, tmp_path / "suzanne.obj", out)
    assert done.returncode == 0, done.stderr[-2000:]
    [lod] = entry["objects"][0]["lods"]
    assert entry["output"] == str(out / "suzanne.obj")
    assert lod["normal_map"] == str(out / "suzanne_Suzanne_normal.png")
    assert sorted(os.listdir(out)) == ["suzanne.mtl", "suzanne.obj", "suzanne_Suzanne_normal.png"]
    obj_lines = (out / "suzanne.obj").read_text().splitlines()
    assert "mtllib suzanne.mtl" in obj_lines and any(line.startswith("usemtl ") for line in obj_lines)
    assert mtl_maps(out / "suzanne.mtl")["map_Bump"] == "suzanne_Suzanne_normal.png"
    assert not (tmp_path / "suzanne.mtl").exists()  # the input's folder is left alone

    written = bpy.data.images.load(lod["normal_map"])
    expected = pixels_of(written)
    obj = reimported(ts, out / "suzanne.obj")
    image = normal_map_image(obj)
    assert image is not None and tuple(image.size) == (SIZE, SIZE)
    assert os.path.samefile(bpy.path.abspath(image.filepath), lod["normal_map"])
    pixels = pixels_of(image)
    assert np.array_equal(pixels, expected) and np.ptp(expected) > 0.3  # the baked map, not a blank one
    assert sum(len(p.vertices) - 2 for p in obj.data.polygons) == lod["triangles"] < 2 * source_faces / 10


def test_an_obj_written_as_gltf_names_the_normal_texture(ts, scene, tmp_path):
    subdivided_suzanne(tmp_path / "suzanne.obj")
    out = tmp_path / "out"
    done, entry = run_batch(ts, tmp_path / "suzanne.obj", out, "--format", "gltf")
    assert done.returncode == 0, done.stderr[-2000:]
    assert entry["output"] == str(out / "suzanne.gltf")
    gltf = json.loads((out / "suzanne.gltf").read_text())
    [material] = gltf["materials"]
    uri = gltf["images"][gltf["textures"][material["normalTexture"]["index"]]["source"]]["uri"]
    assert uri == "suzanne_Suzanne_normal.png" and (out / uri).is_file()
    assert entry["objects"][0]["lods"][0]["normal_map"] == str(out / uri)


def test_an_off_file_goes_through_the_projects_reader(ts, scene, tmp_path):
    """Blender has no OFF importer: the project's reader hands it over as a temporary PLY; the OBJ
    written holds the decimated mesh and names the map."""
    io = importlib_module(ts, "core.api.io")
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24)
    mesh = bpy.context.active_object.data
    mesh.calc_loop_triangles()
    vertices = np.array([v.co[:] for v in mesh.vertices])
    triangles = np.array([t.vertices[:] for t in mesh.loop_triangles], dtype=np.int64)
    io.write_mesh(str(tmp_path / "ball.off"), io.MeshData(vertices=vertices, triangles=triangles))
    out = tmp_path / "out"
    done, entry = run_batch(ts, tmp_path / "ball.off", out, "--format", "obj")
    assert done.returncode == 0, done.stderr[-2000:]
    [lod] = entry["objects"][0]["lods"]
    assert entry["vertices_in"] == len(vertices) and lod["vertices"] < 0.1 * len(vertices)
    assert lod["normal_map"] == str(out / "ball_ball_normal.png") and os.path.isfile(lod["normal_map"])
    assert mtl_maps(out / "ball.mtl")["map_Bump"] == "ball_ball_normal.png"
    written = io.read_mesh(str(out / "ball.obj"))
    assert written.num_triangles == lod["triangles"]


def test_outputs_without_a_material_are_refused(ts, scene, tmp_path):
    subdivided_suzanne(tmp_path / "suzanne.obj")
    for fmt in ("ply", "stl"):
        out = tmp_path / f"out_{fmt}"
        done, entry = run_batch(ts, tmp_path / "suzanne.obj", out, "--format", fmt)
        assert done.returncode == 1 and entry is None
        assert f"a .{fmt} output has no material to reference the baked maps: pass --format obj" in done.stderr
        assert not (out / f"suzanne.{fmt}").exists()


def test_the_colour_map_is_the_mtl_diffuse_map(ts, scene, tmp_path):
    """--bake-colour: the LOD got a UV map of its own (the OBJ has none), so its base colour is
    baked too and the .mtl names it as map_Kd beside the normal map."""
    subdivided_suzanne(tmp_path / "suzanne.obj")
    out = tmp_path / "out"
    done, entry = run_batch(ts, tmp_path / "suzanne.obj", out, "--bake-colour")
    if done.returncode and "Cycles baked no colour" in done.stderr:
        pytest.skip(f"Blender {bpy.app.version_string}'s Cycles bakes no colour selected-to-active")
    assert done.returncode == 0, done.stderr[-2000:]
    [lod] = entry["objects"][0]["lods"]
    assert lod["colour_map"] == str(out / "suzanne_Suzanne_color.png") and os.path.isfile(lod["colour_map"])
    maps = mtl_maps(out / "suzanne.mtl")
    assert (maps["map_Kd"], maps["map_Bump"]) == ("suzanne_Suzanne_color.png", "suzanne_Suzanne_normal.png")
