"""The demo behind the README's main command (scripts/demo.sh).

Imports a mesh (OBJ through Blender, other formats through topstoc.core.api.io; by default the
COLLADA duck bundled in tests/data, which has UV seams), paints
guidance on it the way an artist would (the head: more detail), decimates it with
the Guided Decimate operator at its default settings (Quality: what an artist gets by clicking
it), and writes the scene (.blend), the result (.obj) and a Cycles render with wireframe lines
of the original next to the result (.png).
"""

from __future__ import annotations

import argparse
import os
import pathlib
import sys
import time

import bpy
import numpy as np
from mathutils import Vector

DEFAULT_INPUT = ("tests", "data", "uv_materials", "duck", "duck_via_assimp.obj")


def _default_input() -> str:
    here = pathlib.Path(__file__).resolve()
    for root in here.parents:  # addon/blender/demo.py or build/python/topstoc/blender/demo.py
        candidate = root.joinpath(*DEFAULT_INPUT)
        if candidate.exists():
            return str(candidate)
    return ""


def _load(path: str, scene) -> bpy.types.Object:
    """OBJ through Blender's importer (materials, UVs); other formats through topstoc.core.api.io."""
    if path.lower().endswith(".obj"):
        bpy.ops.wm.obj_import(filepath=path)
        obj = bpy.context.selected_objects[0]
    else:
        from ..core.api import io
        from .io import mesh_write

        data = io.read_mesh(path)
        mesh = bpy.data.meshes.new(pathlib.Path(path).name.split(".")[0])
        mesh_write.fill_geometry(mesh, data.vertices, data.triangles)
        obj = bpy.data.objects.new(mesh.name, mesh)
        scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def _wire_material(name: str, colour) -> bpy.types.Material:
    """A diffuse material with dark wireframe lines (Cycles' Wireframe node)."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    wire = nodes.new("ShaderNodeWireframe")
    wire.use_pixel_size = True
    wire.inputs["Size"].default_value = 1.0
    dark = nodes.new("ShaderNodeBsdfDiffuse")
    dark.inputs["Color"].default_value = (0.02, 0.02, 0.02, 1.0)
    mix = nodes.new("ShaderNodeMixShader")
    links.new(wire.outputs["Fac"], mix.inputs["Fac"])
    links.new(bsdf.outputs["BSDF"], mix.inputs[1])
    links.new(dark.outputs["BSDF"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])
    return material


def _frame(objects, scene) -> None:
    corners = [obj.matrix_world @ Vector(c) for obj in objects for c in obj.bound_box]
    low = Vector([min(c[i] for c in corners) for i in range(3)])
    high = Vector([max(c[i] for c in corners) for i in range(3)])
    centre, size = (low + high) / 2, (high - low)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    if size.y <= size.z:  # look along the thinner of y and z: the larger silhouette faces the camera
        camera.data.ortho_scale = 1.1 * max(size.x, size.z * 2.2)
        camera.location = centre + Vector((0.0, -3.0 * max(size), 0.0))
        camera.rotation_euler = (np.pi / 2, 0.0, 0.0)
    else:
        camera.data.ortho_scale = 1.1 * max(size.x, size.y * 2.2)
        camera.location = centre + Vector((0.0, 0.0, 3.0 * max(size)))
        camera.rotation_euler = (0.0, 0.0, 0.0)
    camera.data.clip_end = 10.0 * max(size)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.rotation_euler = (0.9, 0.2, -0.5)
    sun.data.energy = 4.0
    scene.collection.objects.link(sun)
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.color = (0.8, 0.8, 0.8)


def main(argv=None) -> int:
    from .. import register
    from .operators.guidance import ensure_layer, write_guidance

    if argv is None:
        argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender -b --python topstoc/demo.py --")
    parser.add_argument("--input", default=_default_input())
    parser.add_argument("--ratio", type=float, default=0.1)
    parser.add_argument("--output", default="topstoc-demo")
    parser.add_argument("--samples", type=int, default=16, help="Cycles samples for the render")
    parser.add_argument("--resolution", type=int, default=100, help="render size in %% of 1200 x 560")
    args = parser.parse_args(argv)
    if not args.input or not os.path.exists(args.input):
        print(f"TopStoc demo: error: input mesh '{args.input}' not found", file=sys.stderr)
        return 1
    os.makedirs(args.output, exist_ok=True)
    if not hasattr(bpy.types.Object, "topstoc"):
        register()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types.Object, "topstoc"):
        register()
    scene = bpy.context.scene
    obj = _load(args.input, scene)
    # Guidance as an artist would paint it: the top fifth (the head) keeps more detail. The
    # budget stays the target's, so the rest gets less.
    from .io import mesh_read

    world = np.array(obj.matrix_world)
    points = mesh_read.read_positions(obj.data) @ world[:3, :3].T + world[:3, 3]
    extent = points.max(axis=0) - points.min(axis=0)
    z = points[:, 2] if extent[1] <= extent[2] else points[:, 1]  # "up" as the render shows it
    write_guidance(obj, z >= np.quantile(z, 0.8), None, 0.5)

    # The operator as an artist runs it: the object selected, only the ratio set.
    for other in scene.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    start = time.perf_counter()
    if bpy.ops.topstoc.guided_decimate(ratio=args.ratio) != {"FINISHED"}:
        print("TopStoc demo: error: Guided Decimate did not finish", file=sys.stderr)
        return 1
    seconds = time.perf_counter() - start
    result = bpy.context.view_layer.objects.active  # the operator makes its output active
    width = max(c[0] for c in obj.bound_box) - min(c[0] for c in obj.bound_box)
    result.location.x += 1.15 * width * obj.matrix_world.to_scale().x
    quality = bpy.ops.topstoc.guided_decimate.get_rna_type().properties["quality"]
    summary = (f"TopStoc demo: {obj.name}: {len(obj.data.vertices):,} -> {len(result.data.vertices):,} vertices, "
               f"{len(result.data.polygons):,} triangles in {seconds:.3f} s with output (Guided Decimate at its "
               f"default settings: {quality.enum_items[quality.default].name}; guidance: painted "
               f"'{ensure_layer(obj).name}')")
    print(summary, flush=True)

    stem = os.path.join(args.output, pathlib.Path(args.input).name.split(".")[0] + "_topstoc")
    for other in scene.objects:
        other.select_set(False)
    result.select_set(True)
    bpy.context.view_layer.objects.active = result
    bpy.ops.wm.obj_export(filepath=stem + ".obj", export_selected_objects=True, export_materials=False)
    bpy.context.preferences.filepaths.save_version = 0  # no .blend1 backups
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(stem + ".blend"), copy=True)

    # Render: original (left) and result (right) with wireframe lines.
    for target, colour in ((obj, (0.85, 0.75, 0.4)), (result, (0.95, 0.55, 0.2))):
        target.data.materials.clear()
        target.data.materials.append(_wire_material(f"{target.name} wire", colour))
    _frame([obj, result], scene)
    scene.render.engine = "CYCLES"
    scene.cycles.samples = args.samples
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False  # Debian's Blender is built without OpenImageDenoise
    scene.render.resolution_x, scene.render.resolution_y = 1200, 560
    scene.render.resolution_percentage = args.resolution
    scene.render.filepath = os.path.abspath(stem + ".png")
    bpy.ops.render.render(write_still=True)
    written = f"TopStoc demo: wrote {stem}.blend, {stem}.obj and {stem}.png"
    print(written, flush=True)
    with open(os.path.join(args.output, "summary.txt"), "w") as stream:
        stream.write(summary + "\n" + written + "\n")
    return 0
