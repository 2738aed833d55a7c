"""Run by test_comparison_gui.py in a windowed Blender under Xvfb: the original mesh, Blender's
own Decimate modifier (Collapse) and TopStoc's Guided Decimate (default settings) side by side at
the same triangle count, wireframe on, each labelled with its triangle count and its Hausdorff
error against the original. The screenshot is docs/benchmarks.md's comparison picture
(TOPSTOC_DOC_SHOTS=docs/images keeps it as docs/images/comparison.png).

Arguments after the output folder: the ratio of the input's triangles to ask TopStoc for."""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import session  # noqa: E402
from session import ARGS, check, report, shot  # noqa: E402

ADDON = session.enable_addon()
RATIO = float(ARGS[1]) if len(ARGS) > 1 else 0.05


def triangles_of(obj):
    """(vertices, triangles) of ``obj``'s evaluated mesh in object space (modifiers applied)."""
    from topstoc.blender.io import mesh_read

    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        arrays = mesh_read.read_mesh(mesh)
        return arrays.vertices.copy(), arrays.triangles.copy()
    finally:
        evaluated.to_mesh_clear()


def blender_collapse(source, triangles_wanted):
    """A copy of ``source`` with Blender's Decimate modifier (Collapse, triangulated) whose ratio
    is searched until the evaluated triangle count is the closest to ``triangles_wanted``."""
    copy = source.copy()
    copy.data = source.data.copy()
    copy.name = source.name + "_Collapse"
    source.users_collection[0].objects.link(copy)
    modifier = copy.modifiers.new("Decimate", "DECIMATE")
    modifier.decimate_type = "COLLAPSE"
    modifier.use_collapse_triangulate = True
    low, high = 0.0, 1.0
    best = None
    for _ in range(30):
        modifier.ratio = 0.5 * (low + high)
        count = len(triangles_of(copy)[1])
        if best is None or abs(count - triangles_wanted) < abs(best[1] - triangles_wanted):
            best = (modifier.ratio, count)
        if count == triangles_wanted:
            break
        if count < triangles_wanted:
            low = modifier.ratio
        else:
            high = modifier.ratio
    modifier.ratio = best[0]
    return copy


def view_axes(up_axis):
    """(side, up, towards the viewer) in world space: the view looks along the dragon's thinnest
    axis (X, its side) with its up axis (Y in the CGAL file) up."""
    from mathutils import Vector

    towards = Vector((1.0, 0.0, 0.0))
    up = Vector([1.0 if "xyz"[i] == up_axis else 0.0 for i in range(3)])
    return up.cross(towards).normalized(), up, towards


def label(text, obj, size, axes):
    """A text object centred under ``obj``, facing the viewer."""
    from mathutils import Matrix

    side, up, towards = axes
    curve = bpy.data.curves.new(obj.name + "_label", "FONT")
    curve.body = text
    curve.align_x = "CENTER"
    curve.size = size
    label_object = bpy.data.objects.new(obj.name + "_label", curve)
    obj.users_collection[0].objects.link(label_object)
    corners = [obj.matrix_world @ session.Vector(c) for c in obj.bound_box]
    center = sum(corners, session.Vector()) / 8
    lowest = min(c.dot(up) for c in corners)
    rotation = Matrix((side, up, towards)).transposed().to_4x4()
    label_object.matrix_world = Matrix.Translation(center + (lowest - center.dot(up) - 1.5 * size) * up) @ rotation
    return label_object


def keep_band_for_docs(shot_name, objects, file_name):
    """With TOPSTOC_DOC_SHOTS=DIR, saves the band of the 3D view that holds ``objects`` (the
    view's full width, their rows and a margin) as DIR/file_name."""
    folder = os.environ.get("TOPSTOC_DOC_SHOTS")
    if not folder:
        return
    _window, area, _region, _space = session.view3d()
    pixels = np.load(os.path.join(session.OUT, shot_name + ".npy"))
    rects = [report["regions"][shot_name][o.name] for o in objects]
    margin = 30
    y0 = max(area.y, int(min(r[1] for r in rects)) - margin)
    y1 = min(area.y + area.height - 60, int(max(r[3] for r in rects)) + margin)  # below the header
    band = np.ascontiguousarray(pixels[y0:y1, area.x:area.x + area.width])
    image = bpy.data.images.new(file_name, band.shape[1], band.shape[0], alpha=False)
    image.pixels.foreach_set(band.ravel())
    image.filepath_raw = os.path.join(os.path.abspath(folder), file_name)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def steps():
    from topstoc.core import hausdorff, topology

    original = bpy.data.objects["Dragon"]
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    original.select_set(True)
    bpy.context.view_layer.objects.active = original
    before_vertices, before_triangles = triangles_of(original)
    assert bpy.ops.topstoc.guided_decimate(ratio=RATIO) == {"FINISHED"}
    ours = bpy.data.objects["Dragon_TopStoc"]
    our_vertices, our_triangles = triangles_of(ours)
    theirs = blender_collapse(original, len(our_triangles))
    their_vertices, their_triangles = triangles_of(theirs)
    report["values"]["triangles"] = {"original": len(before_triangles), "topstoc": len(our_triangles),
                                     "collapse": len(their_triangles)}
    check("same triangle count (1 %)", abs(len(their_triangles) - len(our_triangles)) <= 0.01 * len(our_triangles),
          str(report["values"]["triangles"]))
    errors = {}
    for name, (v, t) in {"topstoc": (our_vertices, our_triangles), "collapse": (their_vertices, their_triangles)}.items():
        h = hausdorff((before_vertices, before_triangles), (v, t), relative=True).symmetric
        errors[name] = {"mean": 100 * h.mean, "max": 100 * h.max}
    report["values"]["errors_percent_of_diagonal"] = errors
    genus = {name: [c.genus for c in topology(v, t).components]
             for name, (v, t) in {"original": (before_vertices, before_triangles), "topstoc": (our_vertices, our_triangles),
                                  "collapse": (their_vertices, their_triangles)}.items()}
    report["values"]["genus"] = genus
    check("topstoc keeps the topology", genus["topstoc"] == genus["original"], str(genus))

    # Side by side across the view (which looks along the original's thinnest axis).
    axes = view_axes("y")
    side = axes[0]
    corners = [session.Vector(c) for c in original.bound_box]
    width = max(c.dot(side) for c in (original.matrix_world @ c for c in corners)) - \
        min(c.dot(side) for c in (original.matrix_world @ c for c in corners))
    step = 1.25 * width
    for i, obj in enumerate((original, theirs, ours)):
        obj.matrix_world = original.matrix_world.copy()
        obj.location += i * step * side
        obj.hide_set(False)
    bpy.context.view_layer.update()
    text_size = 0.06 * step

    def caption(title, count, error=None):
        lines = [title, f"{count:,} triangles"]
        if error:
            lines.append(f"error mean {error['mean']:.2f} %, max {error['max']:.2f} %")
        return "\n".join(lines)

    captions = [caption("Original", len(before_triangles)),
                caption("Blender Decimate (Collapse)", len(their_triangles), errors["collapse"]),
                caption("TopStoc (default: Quality)", len(our_triangles), errors["topstoc"])]
    labels = [label(text, obj, text_size, axes) for text, obj in zip(captions, (original, theirs, ours))]
    _window, area, _region, space = session.view3d()
    space.show_region_ui = False
    space.show_region_toolbar = False
    space.overlay.show_text = False
    space.shading.color_type = "OBJECT"  # white captions, light grey meshes
    for obj in (original, theirs, ours):
        obj.show_wire = True
        obj.color = (0.8, 0.8, 0.8, 1.0)
    for obj in labels:
        obj.color = (1.0, 1.0, 1.0, 1.0)
    everything = [original, theirs, ours, *labels]
    corners = [o.matrix_world @ session.Vector(c) for o in everything for c in o.bound_box]
    center = sum(corners, session.Vector()) / len(corners)
    view = space.region_3d
    view.view_perspective = "ORTHO"
    view.view_location = center
    from mathutils import Matrix

    view.view_rotation = Matrix(axes).transposed().to_quaternion()
    half_width = max(abs((c - center).dot(axes[0])) for c in corners)
    view.view_distance = 1.55 * half_width  # orthographic: about 0.55 view_distance shows each side
    space.show_gizmo_navigate = False
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    area.tag_redraw()
    yield 1.0
    shot("comparison", [original, theirs, ours, *labels])
    keep_band_for_docs("comparison", [original, theirs, ours, *labels], "comparison.png")
    pixels = np.load(report["shots"]["comparison"].replace(".png", ".npy"))
    visible = {}
    for name, obj in (("original", original), ("collapse", theirs), ("topstoc", ours)):
        x0, y0, x1, y1 = (int(round(c)) for c in report["regions"]["comparison"][obj.name])
        region = pixels[y0:y1, x0:x1, :3]
        background = np.median(pixels[:, :, :3].reshape(-1, 3), axis=0)
        visible[name] = float((np.abs(region - background).max(axis=-1) > 0.08).mean()) if region.size else 0.0
    report["values"]["visible_fraction"] = visible
    check("each mesh is on screen", all(v > 0.1 for v in visible.values()), str(visible))


session.run(steps)
