"""Runs inside a windowed Blender under Xvfb (imported by the GUI scripts, never by pytest).

A script defines a generator of steps; ``run(steps)`` drives it from a timer (the window must
be drawn between steps), catches every exception (an exception in a timer does not end
Blender), writes ``report.json`` into the output folder and exits with 0 or 1.

Screenshots: ``shot(name)`` saves the whole window as ``<name>.png`` and its pixels as
``<name>.npy`` (rows bottom-up, RGBA 0..1, as Blender's window coordinates), and records
where objects are on screen, so the test can check colours inside an object's region.
"""

import json
import os
import sys
import traceback

import addon_utils
import bpy
import numpy as np
from bpy_extras import view3d_utils
from mathutils import Vector

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
OUT = ARGS[0] if ARGS else os.getcwd()
report = {"checks": {}, "shots": {}, "regions": {}, "values": {}, "error": None}


def enable_addon():
    sys.path.insert(0, os.environ["TOPSTOC_BUILD_PYTHON"])
    if addon_utils.enable("topstoc", default_set=True) is None:
        raise RuntimeError("could not enable the topstoc add-on")
    return sys.modules["topstoc"]


def view3d():
    """(window, area, WINDOW region, space) of the largest 3D view."""
    window = bpy.context.window_manager.windows[0]
    area = max((a for a in window.screen.areas if a.type == "VIEW_3D"), key=lambda a: a.width * a.height)
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, area, region, area.spaces.active


def override():
    window, area, region, _space = view3d()
    return bpy.context.temp_override(window=window, area=area, region=region)


def show_topstoc_tab(panel_class="TOPSTOC_PT_decimate"):
    """Steps (yield from it) that open the sidebar on the TopStoc tab.

    Blender 3.4 has no API to pick a sidebar tab (Region.active_panel_category came later), so
    this clicks down the tab column with simulated events (Blender runs with
    --enable-event-simulate) until one of our panels is drawn.
    """
    _window, area, _region, space = view3d()
    space.show_region_ui = True
    yield 0.3
    cls = getattr(bpy.types, panel_class)
    original_draw = cls.draw
    drawn = []

    def draw(self, context):
        drawn.append(True)
        return original_draw(self, context)

    cls.draw = draw
    try:
        window = bpy.context.window_manager.windows[0]
        sidebar = next(r for r in area.regions if r.type == "UI")
        x = sidebar.x + sidebar.width - 8
        for y in range(sidebar.y + sidebar.height - 15, sidebar.y, -14):
            drawn.clear()
            window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
            window.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
            window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
            area.tag_redraw()
            yield 0.1
            if drawn:
                return
        raise RuntimeError("could not find the TopStoc tab in the sidebar")
    finally:
        cls.draw = original_draw


def frame(objects, tilt=0.45, turn=0.35, distance_factor=2.4):
    """Points the 3D view at ``objects`` along the first object's thinnest local axis (where a
    flat part shows its holes), tilted by ``tilt`` and turned by ``turn`` radians."""
    from mathutils import Matrix, Quaternion

    _w, _a, _r, space = view3d()
    corners = [o.matrix_world @ Vector(c) for o in objects for c in o.bound_box]
    center = sum(corners, Vector()) / len(corners)
    radius = max((c - center).length for c in corners)
    first = objects[0]
    local = [Vector(c) for c in first.bound_box]
    extent = [max(c[i] for c in local) - min(c[i] for c in local) for i in range(3)]
    thin = extent.index(min(extent))
    world = first.matrix_world.to_3x3()
    axis = (world @ Vector([1.0 if i == thin else 0.0 for i in range(3)])).normalized()
    up = (world @ Vector([1.0 if i == (thin + 2) % 3 else 0.0 for i in range(3)])).normalized()
    side = up.cross(axis).normalized()
    up = axis.cross(side).normalized()
    rotation = Matrix((side, up, axis)).transposed().to_quaternion()  # view z axis = towards the viewer
    rotation = rotation @ Quaternion((0, 1, 0), turn) @ Quaternion((1, 0, 0), -tilt)
    view = space.region_3d
    view.view_perspective = "PERSP"
    view.view_location = center
    view.view_rotation = rotation
    view.view_distance = radius * distance_factor
    space.shading.type = "SOLID"
    space.overlay.show_floor = False
    space.overlay.show_axis_x = space.overlay.show_axis_y = False
    space.overlay.show_cursor = False  # its red ring would count as boundary red
    space.show_gizmo_navigate = False


def collapse_first_panel():
    """Steps: a simulated click on the sidebar's first panel header (Guided Decimation) folds it,
    so the panels below it show in the screenshot."""
    _window, area, _region, _space = view3d()
    window = bpy.context.window_manager.windows[0]
    sidebar = next(r for r in area.regions if r.type == "UI")
    x, y = sidebar.x + sidebar.width // 3, sidebar.y + sidebar.height - 14
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
    window.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
    window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
    area.tag_redraw()
    yield 0.3


def screen_rect(obj):
    """Window-pixel rectangle (x0, y0, x1, y1) around ``obj``'s projected bounding box."""
    window, area, region, space = view3d()
    points = [view3d_utils.location_3d_to_region_2d(region, space.region_3d, obj.matrix_world @ Vector(c))
              for c in obj.bound_box]
    points = [p for p in points if p is not None]
    xs = [region.x + p.x for p in points]
    ys = [region.y + p.y for p in points]
    return [max(region.x, min(xs)), max(region.y, min(ys)), min(region.x + region.width, max(xs)),
            min(region.y + region.height, max(ys))]


def view_rect():
    window, area, region, space = view3d()
    return [region.x, region.y, region.x + region.width, region.y + region.height]


def _view_pixels():
    """(window height, width, 4) RGBA of the window with the 3D view's pixels in place, read from
    the view's framebuffer in a draw handler (Blender 4.x: screen.screenshot reads the front
    buffer, which is black under Xvfb). Only the 3D view is filled: every check looks there."""
    import gpu

    window, area, region, _space = view3d()
    captured = []

    def capture():
        x, y, width, height = gpu.state.viewport_get()
        buffer = gpu.state.active_framebuffer_get().read_color(x, y, width, height, 4, 0, "FLOAT")
        # to_list: the Buffer's array interface reports reversed strides in Blender 4.3
        captured.append(np.array(buffer.to_list(), dtype=np.float32).reshape(height, width, 4))

    handler = bpy.types.SpaceView3D.draw_handler_add(capture, (), "WINDOW", "POST_PIXEL")
    try:
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.wm.redraw_timer(type="DRAW", iterations=1)
    finally:
        bpy.types.SpaceView3D.draw_handler_remove(handler, "WINDOW")
    if not captured:
        raise RuntimeError("the 3D view was not drawn for the screenshot")
    pixels = np.zeros((window.height, window.width, 4), dtype=np.float32)
    view = captured[-1][:region.height, :region.width]
    pixels[region.y:region.y + view.shape[0], region.x:region.x + view.shape[1]] = view
    return pixels


def shot(name, objects=()):
    """Screenshot of the whole window -> OUT/name.png and OUT/name.npy; records object rects."""
    path = os.path.join(OUT, name + ".png")
    if bpy.app.version >= (4, 0, 0):
        report["values"]["capture"] = "view framebuffer"
        pixels = _view_pixels()
        image = bpy.data.images.new(name, pixels.shape[1], pixels.shape[0], alpha=True)
        image.pixels.foreach_set(pixels.ravel())
        image.filepath_raw, image.file_format = path, "PNG"
        image.save()
        bpy.data.images.remove(image)
        np.save(os.path.join(OUT, name + ".npy"), pixels)
    else:
        window, area, region, _space = view3d()
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot(filepath=path)
        image = bpy.data.images.load(path)
        pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        np.save(os.path.join(OUT, name + ".npy"), pixels.reshape(image.size[1], image.size[0], 4))
        bpy.data.images.remove(image)
    report["shots"][name] = path
    report["regions"][name] = {"view": view_rect(), **{o.name: screen_rect(o) for o in objects}}


def keep_for_docs(shot_name, file_name):
    """With TOPSTOC_DOC_SHOTS=DIR, saves the 3D view area (with its sidebar) of a screenshot as
    DIR/file_name: how docs/images/*.png are made (see docs/blender-addon.md)."""
    folder = os.environ.get("TOPSTOC_DOC_SHOTS")
    if not folder:
        return
    _window, area, _region, _space = view3d()
    pixels = np.load(os.path.join(OUT, shot_name + ".npy"))
    crop = np.ascontiguousarray(pixels[area.y:area.y + area.height, area.x:area.x + area.width])
    image = bpy.data.images.new(file_name, crop.shape[1], crop.shape[0], alpha=False)
    image.pixels.foreach_set(crop.ravel())
    image.filepath_raw = os.path.join(os.path.abspath(folder), file_name)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def check(name, ok, detail=""):
    report["checks"][name] = bool(ok)
    print(f"gui check {name}: {'ok' if ok else 'FAILED'} {detail}", flush=True)


def _finish(code):
    with open(os.path.join(OUT, "report.json"), "w") as f:
        json.dump(report, f, indent=1)
    sys.stdout.flush()
    os._exit(code)


def run(steps, first_interval=1.0):
    """Drives the generator ``steps`` (it yields seconds to wait) from a timer."""
    state = {}

    def tick():
        try:
            if "steps" not in state:
                state["steps"] = steps()
            return next(state["steps"])
        except StopIteration:
            _finish(0)
        except Exception:
            report["error"] = traceback.format_exc()
            print(report["error"], flush=True)
            _finish(1)

    bpy.app.timers.register(tick, first_interval=first_interval)
