"""A small rigged, shape-keyed character built from scratch (tests and subprocess Blenders).

A closed tube (a subdivided cylinder with capped ends) along Z from 0 to 2, skinned to a
two-bone armature ("Lower" 0..1, "Upper" 1..2, blended around z = 1), with four shape keys:
"Bulge" (radial, slider -1..2), "Twist" (relative to Bulge, B-spline interpolation, limited
to the Upper group), "Muted" (muted) and "Squash". It sits in a collection "Characters",
parented to its armature, with an Armature modifier and a custom property.
"""

import math

import bpy
import numpy as np

RINGS, SEGMENTS = 25, 24


def tube():
    """(vertices, faces) of a capped tube: RINGS x SEGMENTS quads plus two triangle fans."""
    z = np.linspace(0.0, 2.0, RINGS)
    angle = np.linspace(0.0, 2 * math.pi, SEGMENTS, endpoint=False)
    ring = np.stack([0.3 * np.cos(angle), 0.3 * np.sin(angle)], axis=1)
    vertices = [(x, y, h) for h in z for x, y in ring] + [(0.0, 0.0, 0.0), (0.0, 0.0, 2.0)]
    faces = []
    for r in range(RINGS - 1):
        for s in range(SEGMENTS):
            a, b = r * SEGMENTS + s, r * SEGMENTS + (s + 1) % SEGMENTS
            faces.append((a, b, b + SEGMENTS, a + SEGMENTS))
    bottom, top = RINGS * SEGMENTS, RINGS * SEGMENTS + 1
    last = (RINGS - 1) * SEGMENTS
    for s in range(SEGMENTS):
        faces.append((bottom, (s + 1) % SEGMENTS, s))
        faces.append((top, last + s, last + (s + 1) % SEGMENTS))
    return np.array(vertices), faces


def _armature(collection):
    data = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", data)
    collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    lower = data.edit_bones.new("Lower")
    lower.head, lower.tail = (0, 0, 0), (0, 0, 1)
    upper = data.edit_bones.new("Upper")
    upper.head, upper.tail = (0, 0, 1), (0, 0, 2)
    upper.parent = lower
    bpy.ops.object.mode_set(mode="OBJECT")
    return rig


def make_character():
    """Builds the character; returns (mesh object, armature object)."""
    collection = bpy.data.collections.new("Characters")
    bpy.context.scene.collection.children.link(collection)
    rig = _armature(collection)
    vertices, faces = tube()
    mesh = bpy.data.meshes.new("Body")
    mesh.from_pydata(vertices.tolist(), [], faces)
    mesh.update()
    body = bpy.data.objects.new("Body", mesh)
    collection.objects.link(body)
    z = vertices[:, 2]
    upper_weight = np.clip((z - 0.8) / 0.4, 0.0, 1.0)
    for name, weights in (("Lower", 1.0 - upper_weight), ("Upper", upper_weight)):
        group = body.vertex_groups.new(name=name)
        for i, w in enumerate(weights.tolist()):
            if w > 0:
                group.add([i], w, "REPLACE")
    body.parent = rig
    body.matrix_parent_inverse = rig.matrix_world.inverted()
    body.modifiers.new("Armature", "ARMATURE").object = rig
    body["asset_id"] = 42

    body.shape_key_add(name="Basis", from_mix=False)
    radial = np.zeros_like(vertices)
    radial[:, :2] = vertices[:, :2] * np.exp(-((z - 1.0) ** 2) / 0.1)[:, None] * 0.5
    twist = np.zeros_like(vertices)
    t = 0.4 * z
    twist[:, 0] = vertices[:, 0] * np.cos(t) - vertices[:, 1] * np.sin(t) - vertices[:, 0]
    twist[:, 1] = vertices[:, 0] * np.sin(t) + vertices[:, 1] * np.cos(t) - vertices[:, 1]
    squash = np.zeros_like(vertices)
    squash[:, 2] = -0.3 * z
    keys = {}
    for name, offset in (("Bulge", radial), ("Twist", radial + twist), ("Muted", twist), ("Squash", squash)):
        key = body.shape_key_add(name=name, from_mix=False)
        key.data.foreach_set("co", (vertices + offset).astype(np.float32).ravel())
        keys[name] = key
    keys["Bulge"].slider_min, keys["Bulge"].slider_max, keys["Bulge"].value = -1.0, 2.0, 0.7
    keys["Twist"].relative_key = keys["Bulge"]
    keys["Twist"].interpolation = "KEY_BSPLINE"
    keys["Twist"].vertex_group = "Upper"
    keys["Twist"].value = 0.5
    keys["Muted"].mute = True
    keys["Muted"].value = 1.0
    keys["Squash"].value = 0.25
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    body.select_set(True)
    bpy.context.view_layer.objects.active = body
    return body, rig
