"""GUI script (see test_metrics_gui.py): Hausdorff colours and legend, samples and clusters of
the last decimation, the error colour attribute, and the turntable, in a windowed Blender."""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import session  # noqa: E402


def steps():
    session.enable_addon()
    yield from session.show_topstoc_tab("TOPSTOC_PT_metrics")
    yield from session.collapse_first_panel()
    scene = bpy.context.scene
    show = scene.topstoc.overlays
    original = bpy.data.objects["Dragon"]
    decimated = bpy.data.objects["Dragon_TopStoc"]
    window, area, region, space = session.view3d()

    # 1. Error colours on the decimated dragon: absent, shown with a legend, gone when toggled off.
    original.hide_set(True)
    bpy.context.view_layer.objects.active = decimated
    decimated.select_set(False)
    session.frame([decimated])
    yield 0.5
    session.shot("error_off", [decimated])
    show.show_error = True
    yield 0.5
    session.shot("error_on", [decimated])
    session.keep_for_docs("error_on", "hausdorff-colours.png")
    from topstoc.blender.ui import overlays  # the add-on's modules, as registered

    session.report["values"]["drawn_error"] = overlays.drawn_primitives(decimated)
    session.report["values"]["legend_object"] = getattr(overlays.legend_object(bpy.context), "name", None)
    show.show_error = False
    yield 0.5
    session.shot("error_toggled_off", [decimated])

    # 2. The colour attribute: Solid mode's Attribute colour shows the errors without the overlay.
    with session.override():
        result = bpy.ops.topstoc.write_error_colors()
    session.check("write colour attribute", result == {"FINISHED"}
                  and decimated.data.color_attributes.active_color.name == "TopStoc Error")
    space.shading.color_type = "VERTEX"
    yield 0.5
    session.shot("error_attribute", [decimated])
    space.shading.color_type = "MATERIAL"

    # 3. Samples and clusters of the last decimation on the original.
    decimated.hide_set(True)
    original.hide_set(False)
    bpy.context.view_layer.objects.active = original
    session.frame([original])
    yield 0.3
    session.shot("clusters_off", [original])
    show.show_samples = True
    show.show_clusters = True
    yield 0.8
    session.shot("clusters_on", [original])
    session.keep_for_docs("clusters_on", "samples-clusters.png")
    session.report["values"]["drawn_clusters"] = overlays.drawn_primitives(original)
    show.show_clusters = False
    yield 0.5
    session.shot("samples_only", [original])
    show.show_samples = False
    yield 0.3

    # 4. Turntable: two turns, then the view comes back.
    before = space.region_3d.view_rotation.copy()
    with session.override():
        result = bpy.ops.topstoc.turntable("INVOKE_DEFAULT", duration=4.0)
    session.check("turntable starts", result == {"RUNNING_MODAL"})
    import time
    start = time.perf_counter()
    rotations = []
    for _ in range(6):
        yield 0.4
        rotations.append(tuple(space.region_3d.view_rotation) + (time.perf_counter() - start,))
    session.report["values"]["turntable_rotations"] = rotations
    yield 3.0
    after = space.region_3d.view_rotation
    session.check("turntable moved the view", len({tuple(round(v, 3) for v in r) for r in rotations}) >= 4)
    session.check("turntable restores the view", before.rotation_difference(after).angle < 1e-4)


session.run(steps)
