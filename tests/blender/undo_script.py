"""Run by test_undo.py in a windowed Blender (under Xvfb): undo needs a window, which
`blender -b` lacks. Prints one line per check and exits 0 only when all hold."""

import os
import sys

import addon_utils
import bpy

build = os.environ["TOPSTOC_BUILD_PYTHON"]
sys.path.insert(0, build)
failures = []


def check(name, ok):
    print(f"undo check {name}: {'ok' if ok else 'FAILED'}", flush=True)
    if not ok:
        failures.append(name)


try:
    addon_utils.enable("topstoc", default_set=True)
    bpy.ops.mesh.primitive_torus_add("EXEC_DEFAULT", True, major_segments=64, minor_segments=24)
    name = bpy.context.object.name  # undo replaces Python references: look objects up by name
    before = len(bpy.data.objects[name].data.vertices)
    bpy.ops.topstoc.guided_decimate("EXEC_DEFAULT", True, ratio=0.2)  # True: push undo as the UI does
    check("new object added", f"{name}_TopStoc" in bpy.data.objects)
    bpy.ops.ed.undo()
    check("undo removes the new object", f"{name}_TopStoc" not in bpy.data.objects
          and len(bpy.data.objects[name].data.vertices) == before)
    bpy.context.view_layer.objects.active = bpy.data.objects[name]
    bpy.data.objects[name].select_set(True)
    result = bpy.ops.topstoc.guided_decimate("EXEC_DEFAULT", True, ratio=0.2, output="IN_PLACE")
    check("decimated in place", result == {"FINISHED"} and len(bpy.data.objects[name].data.vertices) < before)
    after = len(bpy.data.objects[name].data.vertices)
    bpy.ops.ed.undo()
    check("undo restores the mesh", len(bpy.data.objects[name].data.vertices) == before)
    bpy.ops.ed.redo()
    check("redo decimates again", len(bpy.data.objects[name].data.vertices) == after)
except Exception as error:  # report, never hang the windowed Blender
    import traceback

    traceback.print_exc()
    failures.append(repr(error))
sys.stdout.flush()
os._exit(1 if failures else 0)
