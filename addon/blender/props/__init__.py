"""Settings stored in .blend files: guidance sources per object, decimation defaults per scene."""

from __future__ import annotations

import math

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, PointerProperty, StringProperty)

from ...core.api.decimate import ATTRIBUTE_WEIGHT
from . import results as props_analysis
from .results import TOPSTOC_PG_metrics, TOPSTOC_PG_overlays, TOPSTOC_PG_topology

#: Material slots that can carry a guidance weight (later slots count as 0).
MAX_MATERIAL_SLOTS = 32
DEFAULT_COLOR_LAYER = "TopStoc Guidance"

TARGET_MODES = [
    ("RATIO", "Vertex Ratio", "Keep this fraction of the vertices (on a closed mesh about the same fraction of "
                              "the faces; Blender's Decimate counts faces)"),
    ("VERTICES", "Vertices", "Number of output vertices"),
    ("TRIANGLES", "Triangles", "Number of output triangles"),
    ("MAX_ERROR", "Max Deviation", "Largest allowed Hausdorff deviation from the original"),
]
DENSITY_MODES = [
    ("off", "Free", "Kept vertices may lie close together"),
    ("uniform", "Even", "Kept vertices stay at least one edge ring apart: more even triangles"),
    ("adaptive", "By Detail", "Kept vertices lie further apart where the surface is flat (thesis 4.1.2)"),
]
OUTPUT_MODES = [
    ("NEW_OBJECT", "New Object", "Put the result in a new object beside the original (offset along X by its "
                                 "width); a rigged original stays where it is and is hidden instead"),
    ("IN_PLACE", "In Place", "Replace the object's mesh (undo restores it)"),
]
SYMMETRY_AXES = [("X", "X", "Mirror across the object's local YZ plane"),
                 ("Y", "Y", "Mirror across the object's local XZ plane"),
                 ("Z", "Z", "Mirror across the object's local XY plane")]
PLACEMENTS = [
    ("subsample", "Original", "Every vertex of the result is a vertex of the original: UVs, colours and "
                              "weights copy exactly"),
    ("filtered", "Best Fit", "Vertices move to the point that keeps the shape best (quadric error)"),
]
QUALITY_MODES = [
    ("QUALITY", "Quality", "TopStoc to a few times the target, then edge collapses by quadric error: the "
                           "cleanest result (the live preview shows it when the drag pauses)"),
    ("BEST", "Best", "Quality, then a result of more than 1,400 triangles is fitted to the original as "
                     "smaller ones always are: about 10 % lower mean deviation on scans for about 1.5 times "
                     "Quality's time (meshes of up to 250,000 vertices; the live preview's pause takes as long)"),
    ("FAST", "Fast", "The thesis' plain TopStoc: output vertices are input vertices; milliseconds, higher "
                     "deviation (what the live preview shows while dragging)"),
    ("CUSTOM", "Custom", "Plain TopStoc with the Placement and Refine settings under Advanced"),
]


class DecimationParameters:
    """Decimation parameters shared by the operators and the scene defaults (a mixin)."""

    target_mode: EnumProperty(name="Target", items=TARGET_MODES, default="RATIO")
    ratio: FloatProperty(name="Keep", description="Fraction of the vertices to keep (0.1: one in ten)",
                         default=0.1, min=1e-6, max=1.0, soft_min=0.001, precision=4,
                         subtype="FACTOR")
    vertices: IntProperty(name="Vertices", description="Number of output vertices", default=1000, min=1)
    triangles: IntProperty(name="Triangles", description="Number of output triangles", default=2000, min=1)
    max_error: FloatProperty(name="Max Deviation", description="Largest allowed deviation", default=1.0,
                             min=0.0, precision=4)
    max_error_relative: BoolProperty(name="Percent of Diagonal",
                                     description="Max deviation in % of the bounding-box diagonal",
                                     default=True)
    quality: EnumProperty(name="Quality", items=QUALITY_MODES, default="QUALITY",
                          description="Fast or lower-deviation result (Custom: the Advanced settings)")
    use_symmetry: BoolProperty(name="Symmetry", default=False,
                               description="A mirror-symmetric mesh gives a mirror-symmetric result "
                                           "(as the Decimate modifier's Symmetry)")
    symmetry_axis: EnumProperty(name="Axis", items=SYMMETRY_AXES, default="X",
                                description="Local axis across which the mesh mirrors")
    seed: IntProperty(name="Seed", description="The same seed gives the same result", default=0, min=0)
    adaptivity: FloatProperty(name="Curvature",
                              description="How much more detail curved parts keep than flat ones: 0 spreads the "
                                          "vertices evenly, 1 puts them where the surface bends",
                              default=0.5, min=0.0, max=1.0, subtype="FACTOR")
    density: EnumProperty(name="Spacing", items=DENSITY_MODES, default="off",
                          description="How far apart the kept vertices must be (Poisson-disk rejection)")
    placement: EnumProperty(name="Position", items=PLACEMENTS, default="subsample",
                            description="Where the result's vertices go (when Quality is Custom)")
    refine: IntProperty(name="Clean-Up", default=0, min=0, max=32,
                        description="When Quality is Custom. 0: off (fastest). N: first keep N times the target, "
                                    "then remove the vertices whose loss changes the shape least (quadric edge "
                                    "collapses): slower, closer to the original")
    attribute_weight: FloatProperty(
        name="Appearance", default=ATTRIBUTE_WEIGHT, min=0.0, soft_max=1.0, precision=3,
        description="How much Quality mode protects the look: the active UV map, the colour attribute "
                    "(never the guidance paint) and custom normals are weighed with the shape, so textures "
                    "stretch less, colours smear less and hard-surface shading stays. A UV or colour "
                    "difference of 1, or normals about 1 radian apart, costs like moving the surface by this "
                    "fraction of the object's size. 0: shape only. Fast mode ignores it")
    output: EnumProperty(name="Output", items=OUTPUT_MODES, default="NEW_OBJECT")


BAKE_SIZES = [(str(2 ** k), f"{2 ** k}", f"A {2 ** k} x {2 ** k} normal map") for k in range(8, 14)]
BAKE_STORES = [("PACK", "Pack", "Pack the normal map into the .blend file"),
               ("FILE", "Beside .blend", "Save the normal map as a PNG beside the saved .blend file")]


class BakeParameters:
    """The "Bake Normals" option of Guided Decimate and the LOD chain (a mixin; blender/decimation/bake.py)."""

    bake_normals: BoolProperty(name="Bake Normals", default=False,
                               description="Bake a tangent-space normal map from the original onto each new "
                                           "result (Cycles on the CPU), so a low LOD still shades like it")
    bake_size: EnumProperty(name="Resolution", items=BAKE_SIZES, default="1024",
                            description="Width and height of the normal map in pixels")
    bake_margin: IntProperty(name="Margin", default=16, min=0, max=64, subtype="PIXEL",
                             description="Pixels the map bleeds past every UV island (against seams in mipmaps)")
    bake_store: EnumProperty(name="Image", items=BAKE_STORES, default="PACK")
    bake_colour: BoolProperty(name="Bake Colour", default=False,
                              description="Also bake the original's base colour and its image-textured Roughness, "
                                          "Metallic, Emission and Alpha, where the normal map gets a UV map of its "
                                          "own (the original has none, or one with overlapping islands)")


class OperatorParameters:
    """DecimationParameters for operators (a mixin). They are not remembered between calls
    (SKIP_SAVE): Blender would otherwise fill them from the last call and mark them as set, so
    the panel's settings could not fill what a call leaves out (see fill_from_scene)."""


def _skip_save(annotation):
    # annotations are strings here (from __future__ import annotations): evaluate them first
    deferred = eval(annotation, globals()) if isinstance(annotation, str) else annotation
    return deferred.function(**dict(deferred.keywords, options={"SKIP_SAVE"}))


OperatorParameters.__annotations__ = {name: _skip_save(annotation)
                                      for name, annotation in DecimationParameters.__annotations__.items()}


class OperatorBakeParameters:
    """BakeParameters for operators, not remembered between calls (as OperatorParameters)."""


OperatorBakeParameters.__annotations__ = {name: _skip_save(annotation)
                                          for name, annotation in BakeParameters.__annotations__.items()}


def copy_parameters(source, target) -> None:
    """Copies every DecimationParameters property from one holder to another."""
    for name in DecimationParameters.__annotations__:
        setattr(target, name, getattr(source, name))


def explicit_engine_options(operator) -> None:
    """A call that sets Placement or Refine but not Quality means those values: Quality becomes
    Custom (scripts written before the Quality choice keep working; the redo panel too)."""
    is_set = operator.properties.is_property_set
    if (is_set("placement") or is_set("refine")) and not is_set("quality"):
        operator.quality = "CUSTOM"


def settings_names() -> list:
    """Names of the DecimationParameters properties."""
    return list(DecimationParameters.__annotations__)


def fill_from_scene(operator, scene_settings) -> None:
    """An operator's invoke: the scene's settings, except the properties the caller set
    explicitly (a script's or keymap's ``output='IN_PLACE'`` wins over the panel)."""
    for name in DecimationParameters.__annotations__:
        if not operator.properties.is_property_set(name):
            setattr(operator, name, getattr(scene_settings, name))
    for name in BakeParameters.__annotations__:  # operators with the Bake Normals option
        if hasattr(operator.properties, name) and not operator.properties.is_property_set(name):
            setattr(operator, name, getattr(scene_settings, name))


class TOPSTOC_PG_sample_set(bpy.types.PropertyGroup):
    """A saved decimation: parameters, fingerprints and the sample ids (custom property)."""

    parameters: StringProperty(name="Parameters", description="JSON")
    mesh_digest: StringProperty(name="Mesh Fingerprint")
    layout_digest: StringProperty(name="Border Fingerprint")
    vertices_out: IntProperty(name="Vertices")
    triangles_out: IntProperty(name="Triangles")


class TOPSTOC_PG_object(bpy.types.PropertyGroup):
    """Guidance sources of a mesh object, and box settings of an empty."""

    use_vertex_group: BoolProperty(name="Vertex Group", description="Guidance from a vertex group")
    vertex_group: StringProperty(name="Group", description="Vertex group giving guidance")
    vertex_group_mapping: EnumProperty(
        name="Mapping", default="DETAIL",
        items=[("DETAIL", "Detail", "Weight = detail, u = w: weight 1 keeps every vertex, 0 is neutral"),
               ("SIGNED", "Signed", "u = 2w - 1: 1 keeps, 0.5 neutral, 0 drops"),
               ("DECIMATE", "Inverse", "u = 1 - w: weight 0 locks, 1 neutral (as Blender's Decimate modifier)")])
    vertex_group_strength: FloatProperty(name="Strength", default=1.0, min=0.0, max=1.0, subtype="FACTOR")

    use_color: BoolProperty(name="Painted Guidance",
                            description="Guidance painted in Vertex Paint mode or set on a selection "
                                        "(orange = more detail, grey = neutral, blue = less)",
                            default=True)
    color_attribute: StringProperty(name="Color Attribute", default=DEFAULT_COLOR_LAYER)
    color_strength: FloatProperty(name="Strength", default=1.0, min=0.0, max=1.0, subtype="FACTOR")

    use_uv_seams: BoolProperty(name="Keep UV Seams", description="No cluster crosses a UV seam", default=True)
    use_materials: BoolProperty(name="Keep Material Borders",
                                description="No cluster crosses a border between material slots",
                                default=True)
    material_weights: FloatVectorProperty(name="Slot Weights", size=MAX_MATERIAL_SLOTS, min=-1.0, max=1.0,
                                          description="Guidance per material slot (-1 less ... 1 keep)")
    material_strength: FloatProperty(name="Strength", default=1.0, min=0.0, max=1.0, subtype="FACTOR")
    use_sharp: BoolProperty(name="Keep Sharp Edges", description="No cluster crosses an edge marked sharp",
                            default=False)
    use_hard_normals: BoolProperty(name="Keep Hard Normals",
                                   description="No cluster crosses a hard edge of the custom normals (where "
                                               "their shading breaks), so each side keeps its own normals",
                                   default=True)

    box_enabled: BoolProperty(name="Guidance Box",
                              description="This cube empty sets the guidance of the vertices inside it")
    box_weight: FloatProperty(name="Box Weight", default=1.0, min=-1.0, max=1.0,
                              description="Guidance inside the box (-1 drop ... 1 keep)")

    source: PointerProperty(type=bpy.types.Object, name="Source",
                            description="The object this result was decimated from (Regenerate re-runs it)")
    settings: StringProperty(name="Settings", description="The decimation settings of this result (JSON)")
    auto_regenerate: BoolProperty(name="Auto Regenerate", default=False,
                                  description="Regenerate this result shortly after its source changes")

    sample_sets: CollectionProperty(type=TOPSTOC_PG_sample_set)
    sample_set_index: IntProperty(name="Sample Set")

    topology: PointerProperty(type=TOPSTOC_PG_topology)   #: the Topology panel's results
    metrics: PointerProperty(type=TOPSTOC_PG_metrics)     #: the Metrics panel's results


class TOPSTOC_PG_scene(DecimationParameters, BakeParameters, bpy.types.PropertyGroup):
    """Scene-wide defaults: decimation parameters, boxes, view, multiview and LODs."""

    use_boxes: BoolProperty(name="Guidance Boxes", description="Use cube empties marked as guidance boxes",
                            default=True)
    box_strength: FloatProperty(name="Strength", default=1.0, min=0.0, max=1.0, subtype="FACTOR")

    use_view: BoolProperty(name="View-Dependent", description="Fewer vertices on back faces, keep silhouettes")
    view_source: EnumProperty(name="View", default="CAMERA",
                              items=[("CAMERA", "Camera", "The scene's active camera"),
                                     ("VIEWPORT", "Viewport", "The current 3D viewport view")])
    back_ratio: FloatProperty(name="Back-Face Ratio", default=0.25, min=0.0, max=1.0, subtype="FACTOR")
    silhouette_angle: FloatProperty(name="Silhouette Band", default=math.radians(20.0), min=0.0,
                                    max=math.radians(90.0), subtype="ANGLE")
    silhouette_falloff: FloatProperty(name="Fall-Off", default=0.1, min=0.0, max=1.0)
    use_frustum: BoolProperty(name="Cull Outside View", default=False)
    outside_probability: FloatProperty(name="Outside Probability", default=0.0, min=0.0, max=1.0,
                                       subtype="FACTOR")

    variants: IntProperty(name="Variants", default=4, min=1, max=32)
    variance: FloatProperty(name="Variance", description="± change of the target across the variants",
                            default=0.25, min=0.0, max=0.95, subtype="FACTOR")
    lod_ratios: StringProperty(name="LOD Ratios", default="1.0, 0.5, 0.25, 0.1",
                               description="Vertex ratios, comma-separated, LOD0 (the finest) first")

    overlays: PointerProperty(type=TOPSTOC_PG_overlays)


CLASSES = props_analysis.CLASSES + (TOPSTOC_PG_sample_set, TOPSTOC_PG_object, TOPSTOC_PG_scene)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Object.topstoc = PointerProperty(type=TOPSTOC_PG_object)
    bpy.types.Scene.topstoc = PointerProperty(type=TOPSTOC_PG_scene)


def unregister():
    del bpy.types.Scene.topstoc
    del bpy.types.Object.topstoc
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
