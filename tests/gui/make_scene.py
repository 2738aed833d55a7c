"""Builds a saved scene for the GUI tests (run in `blender -b --factory-startup`).

    blender -b --factory-startup --python make_scene.py -- --mesh FILE --output SCENE.blend
        [--name NAME] [--subdivide LEVELS] [--transform] [--decimate RATIO] [--measure]
        [--analyse] [--loops] [--pinched-handles N]

Reads any mesh format through topstoc.core.api.io; --subdivide splits every triangle into four
(midpoint subdivision: same shape and topology, more triangles); --pinched-handles adds N thin
arches, a scanner's bridges (tests/cleanup_meshes.py, seed 1); --transform moves, rotates and
scales the object non-uniformly (overlays must follow); --decimate adds "<name>_TopStoc" at the
same place (moved back from beside the original); --measure stores the Hausdorff figures on the decimated object; --analyse and
--loops store the topology and the handle/tunnel loops on the mesh. The default scene's cube
is removed. Exits non-zero on any failure.
"""

import argparse
import math
import os
import sys

import addon_utils
import bpy


def parse(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--name", default="Mesh")
    parser.add_argument("--subdivide", type=int, default=0)
    parser.add_argument("--transform", action="store_true")
    parser.add_argument("--decimate", type=float)
    parser.add_argument("--measure", action="store_true")
    parser.add_argument("--analyse", action="store_true")
    parser.add_argument("--loops", action="store_true")
    parser.add_argument("--pinched-handles", type=int, default=0)
    return parser.parse_args(argv)


def main():
    args = parse(sys.argv[sys.argv.index("--") + 1:])
    sys.path.insert(0, os.environ["TOPSTOC_BUILD_PYTHON"])
    if addon_utils.enable("topstoc", default_set=True) is None:
        raise RuntimeError("could not enable topstoc")
    from topstoc.blender.io import mesh_write
    from topstoc.core.api import io

    cube = bpy.data.objects.get("Cube")
    if cube is not None:
        bpy.data.objects.remove(cube)
    data = io.read_mesh(args.mesh)
    vertices, triangles = data.vertices, data.triangles
    if args.subdivide:
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
        import meshgen

        vertices, triangles = meshgen.subdivide(vertices, triangles, args.subdivide)
    if args.pinched_handles:
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
        import cleanup_meshes

        vertices, triangles, _arches = cleanup_meshes.with_pinched_handles(vertices, triangles, args.pinched_handles,
                                                                           seed=1)
    mesh = bpy.data.meshes.new(args.name)
    mesh_write.fill_geometry(mesh, vertices, triangles)
    obj = bpy.data.objects.new(args.name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    if args.transform:
        obj.location = (0.7, -0.4, 0.3)
        obj.rotation_euler = (math.radians(30), math.radians(-20), math.radians(50))
        obj.scale = (1.4, 0.8, 1.1)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    if args.analyse or args.loops:
        assert bpy.ops.topstoc.analyse() == {"FINISHED"}
    if args.loops:
        assert bpy.ops.topstoc.find_loops() == {"FINISHED"}
    if args.decimate:
        assert bpy.ops.topstoc.guided_decimate(ratio=args.decimate) == {"FINISHED"}
        out = bpy.data.objects[args.name + "_TopStoc"]
        out.matrix_world = obj.matrix_world.copy()  # on top of the original (the output goes beside it)
        if args.measure:
            bpy.context.view_layer.objects.active = out
            assert bpy.ops.topstoc.measure() == {"FINISHED"}
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.output))


try:
    main()
except Exception:
    import traceback

    traceback.print_exc()
    sys.exit(1)
