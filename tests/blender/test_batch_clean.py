"""The Blender batch's --clean: each mesh of a scene cleaned (handles, holes) before it is
decimated, attributes carried; topology checked with the Euler characteristic of the output."""

import json

import bpy
import numpy as np
import pytest

from conftest import DATA, PACKAGE
from launch import background

MAKE_SCENE = """
import sys, bpy
sys.path.insert(0, {tests!r})
import cleanup_meshes
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
meshes = (("Arches", cleanup_meshes.block_with_arches(3, 1, jitter=0.05, seed=3)),
          ("Plate", cleanup_meshes.perforated_plate(3, 1, side=24, seed=4)))
for name, (v, f) in meshes:
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(v.tolist(), [], f.tolist())
    bpy.context.scene.collection.objects.link(bpy.data.objects.new(name, mesh))
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""


def _euler_and_border(mesh):
    """(V - E + F, boundary edges) of a Blender mesh, from its polygons."""
    edges = {}
    for polygon in mesh.polygons:
        ring = list(polygon.vertices)
        for a, b in zip(ring, ring[1:] + ring[:1]):
            key = (min(a, b), max(a, b))
            edges[key] = edges.get(key, 0) + 1
    return len(mesh.vertices) - len(edges) + len(mesh.polygons), sum(1 for n in edges.values() if n == 1)


def test_blend_batch_clean(ts, scene, tmp_path):
    source = tmp_path / "scene.blend"
    done = background(expr=MAKE_SCENE.format(tests=str(DATA.parent), path=str(source)), timeout=120)
    assert done.returncode == 0 and source.exists(), done.stdout[-2000:] + done.stderr[-2000:]
    before = source.read_bytes()
    report = tmp_path / "report.json"
    done = background(PACKAGE / "batch.py", "--input", source, "--ratio", "0.6", "--clean", "--max-handle", "6",
                      "--max-hole", "6", "--output", tmp_path / "out", "--json", report, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert source.read_bytes() == before
    [result] = json.loads(report.read_text())["results"]
    entries = {entry["object"]: entry for entry in result["objects"]}
    arches, plate = entries["Arches"]["clean"], entries["Plate"]["clean"]
    assert (arches["genus_before"], arches["genus_after"], arches["handles_removed"]) == (4, 1, 3)
    assert plate["holes_filled"] == 3 and len([i for i in plate["left"] if i["kind"] == "hole"]) == 2
    try:
        bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "out" / "scene.blend"))
    except RuntimeError as error:
        pytest.skip(f"this Blender cannot read the batch Blender's file: {error}")
    # A closed surface of genus 1: chi 0; a disk with one hole left: chi 0 with a border.
    assert _euler_and_border(bpy.data.objects["Arches"].data) == (0, 0)
    chi, border = _euler_and_border(bpy.data.objects["Plate"].data)
    assert chi == 0 and border > 0
    assert len(bpy.data.objects["Arches"].data.vertices) == entries["Arches"]["vertices_out"]
