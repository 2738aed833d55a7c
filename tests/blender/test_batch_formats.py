"""glTF/GLB, FBX and USD through the batch: a skinned, shape-keyed, two-material, UV-mapped and
vertex-coloured character built here, written with Blender's exporter, batched (one Blender per
asset, as `topstoc batch` runs it: this Blender's executable, or this Python with PyPI's bpy),
and read back with Blender's importer. Every attribute of the output is compared with the input
read back the same way, at the same positions (TopStoc's output vertices are input vertices)."""

import argparse
import importlib
import json
import shutil
import sys

import bpy
import numpy as np
import pytest

FORMATS = ["glb", "gltf", "fbx", "usdc"]


def _runner():
    """What runs the batch's Blender: this Blender's executable, or this Python (bpy module)."""
    if bpy.app.binary_path and not bpy.app.binary_path.endswith(("python", "python3")) and \
            "python" not in bpy.app.binary_path.rsplit("/", 1)[-1]:
        return bpy.app.binary_path
    return sys.executable


def _settings(ts, *argv):
    batch_settings = importlib.import_module(ts.__name__ + ".core.batch.settings")
    parser = argparse.ArgumentParser()
    batch_settings.add_arguments(parser)
    # Fast mode: output vertices are input vertices, so attributes can be compared exactly.
    return batch_settings.from_args(parser.parse_args([*argv, "--mode", "fast"]))


def _character():
    """A UV sphere ('Body') with two materials, a corner colour layer, two shape keys and an
    armature of two bones weighting its lower and upper half."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, radius=1.0)
    body = bpy.context.active_object
    body.name = "Body"
    bpy.ops.object.shade_smooth()
    mesh = body.data
    for name in ("Skin", "Cloth"):
        mesh.materials.append(bpy.data.materials.new(name))
    for polygon in mesh.polygons:
        polygon.material_index = int(polygon.center.z < 0)
    # Point colours: Blender < 3.5's glTF exporter writes corner colours wrongly (by vertex index).
    colours = mesh.color_attributes.new("Col", "BYTE_COLOR", "POINT")
    for vertex in mesh.vertices:
        co = vertex.co
        colours.data[vertex.index].color = (0.5 + 0.5 * co.x, 0.5 + 0.5 * co.y, 0.5 + 0.5 * co.z, 1.0)
    body.shape_key_add(name="Basis")
    bulge = body.shape_key_add(name="Bulge")
    for i, vertex in enumerate(mesh.vertices):
        if vertex.co.z > 0:
            bulge.data[i].co = vertex.co * 1.25
    armature = bpy.data.objects.new("Rig", bpy.data.armatures.new("Rig"))
    bpy.context.scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    for name, head, tail in (("Lower", (0, 0, -1), (0, 0, 0)), ("Upper", (0, 0, 0), (0, 0, 1))):
        bone = armature.data.edit_bones.new(name)
        bone.head, bone.tail = head, tail
    armature.data.edit_bones["Upper"].parent = armature.data.edit_bones["Lower"]
    bpy.ops.object.mode_set(mode="OBJECT")
    lower, upper = body.vertex_groups.new(name="Lower"), body.vertex_groups.new(name="Upper")
    for vertex in mesh.vertices:
        w = float(np.clip(0.5 + vertex.co.z, 0.0, 1.0))
        upper.add([vertex.index], w, "REPLACE")
        lower.add([vertex.index], 1.0 - w, "REPLACE")
    body.parent = armature
    modifier = body.modifiers.new("Armature", "ARMATURE")
    modifier.object = armature
    return body


def _export(path, kind):
    if kind in ("glb", "gltf"):
        bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB" if kind == "glb" else "GLTF_SEPARATE")
    elif kind == "fbx":
        bpy.ops.export_scene.fbx(filepath=str(path), add_leaf_bones=False)
    else:
        bpy.ops.wm.usd_export(filepath=str(path), export_armatures=True, export_shapekeys=True)


def _is_bone_shape(obj):
    """The glTF importer of Blender 4.x adds an "Icosphere" mesh to draw bones with."""
    return any(bone.custom_shape == obj for arm in bpy.context.scene.objects if arm.type == "ARMATURE"
               for bone in arm.pose.bones)


def _read_back(ts, path):
    """Imports ``path`` with Blender's importer; per-corner data of its one mesh object."""
    scene_io = importlib.import_module(ts.__name__ + ".blender.io.scene_files")
    scene_io.import_file(str(path))
    [obj] = [o for o in bpy.context.scene.objects if o.type == "MESH" and not _is_bone_shape(o)]
    mesh = obj.data
    # World space: importers differ in where they put the axis conversion (object or vertices).
    matrix = np.array(obj.matrix_world)
    linear, offset = matrix[:3, :3], matrix[:3, 3]
    positions = np.array([v.co[:] for v in mesh.vertices]) @ linear.T + offset
    corners = np.array([loop.vertex_index for loop in mesh.loops])
    face_of_corner = np.repeat(np.arange(len(mesh.polygons)), [p.loop_total for p in mesh.polygons])
    uvs = np.array([d.uv[:] for d in mesh.uv_layers.active.data]) if mesh.uv_layers else None
    colours = None
    if len(mesh.color_attributes):
        attribute = mesh.color_attributes[0]
        values = np.array([d.color[:3] for d in attribute.data])
        colours = values[corners] if attribute.domain == "POINT" else values
    materials = [mesh.materials[p.material_index].name.split(".")[0] if mesh.materials else None
                 for p in mesh.polygons]
    keys = {}
    if mesh.shape_keys is not None:
        for block in mesh.shape_keys.key_blocks[1:]:
            keys[block.name] = np.array([d.co[:] for d in block.data]) @ linear.T + offset - positions
    names = {g.index: g.name for g in obj.vertex_groups}
    weights = [{names[g.group]: g.weight for g in v.groups if g.weight > 0} for v in mesh.vertices]
    deformers = [m.object.name if m.object else None for m in obj.modifiers if m.type == "ARMATURE"]
    parent = obj.parent.type if obj.parent else None
    return dict(positions=positions, corners=corners, face=face_of_corner, uvs=uvs, colours=colours,
                materials=materials, keys=keys, weights=weights, polygons=len(mesh.polygons),
                armature=bool(deformers) or parent == "ARMATURE",
                bones=sorted(b.name for o in bpy.context.scene.objects if o.type == "ARMATURE" for b in o.data.bones))


def _key(position):
    return tuple(np.round(position, 4))


def _assert_follows_the_input(source, output):
    """Every output corner carries, at its position, attributes the input has there."""
    by_position = {}
    for corner, vertex in enumerate(source["corners"]):
        entry = by_position.setdefault(_key(source["positions"][vertex]), {"uv": set(), "colour": [], "vertex": vertex})
        entry["uv"].add(tuple(np.round(source["uvs"][corner], 4)))
        entry["colour"].append(source["colours"][corner] if source["colours"] is not None else None)
    seam_vertices = 0
    for vertex, position in enumerate(output["positions"]):
        assert _key(position) in by_position, "an output vertex that is not an input vertex"
    for corner, vertex in enumerate(output["corners"]):
        entry = by_position[_key(output["positions"][vertex])]
        assert tuple(np.round(output["uvs"][corner], 4)) in entry["uv"]
        if output["colours"] is not None:
            assert np.allclose(output["colours"][corner], entry["colour"][0], atol=2e-2)
    uv_per_position = {}
    for corner, vertex in enumerate(output["corners"]):
        uv_per_position.setdefault(_key(output["positions"][vertex]), set()).add(
            tuple(np.round(output["uvs"][corner], 4)))
    seam_vertices = sum(len(uvs) > 1 for uvs in uv_per_position.values())
    assert seam_vertices > 0, "the UV seam did not survive"
    # Materials: each output face takes the material of the input face nearest its centre.
    centres_in = np.array([source["positions"][source["corners"][source["face"] == f]].mean(axis=0)
                           for f in range(source["polygons"])])
    for f in range(output["polygons"]):
        centre = output["positions"][output["corners"][output["face"] == f]].mean(axis=0)
        assert np.sign(centre[2]) == np.sign(centres_in[np.argmin(np.linalg.norm(centres_in - centre, axis=1))][2]) \
            or abs(centre[2]) < 0.2
        expected = "Cloth" if centre[2] < -0.2 else "Skin" if centre[2] > 0.2 else None
        if expected:
            assert output["materials"][f] == expected
    # Skin weights and shape-key offsets at each vertex equal the input's at that position.
    index_in = {_key(p): i for i, p in enumerate(source["positions"])}
    for vertex, position in enumerate(output["positions"]):
        i = index_in[_key(position)]
        assert set(output["weights"][vertex]) == set(source["weights"][i])
        for group, weight in output["weights"][vertex].items():
            assert weight == pytest.approx(source["weights"][i][group], abs=1e-3)


@pytest.mark.parametrize("kind", FORMATS)
def test_round_trip_keeps_what_the_add_on_keeps(ts, scene, tmp_path, kind):
    if kind.startswith("usd") and not bpy.app.build_options.usd:
        pytest.skip(f"Blender {bpy.app.version_string} is built without USD")
    _character()
    source = tmp_path / f"character.{kind}"
    _export(source, kind)
    batch_run = importlib.import_module(ts.__name__ + ".core.batch.run")
    out = tmp_path / "out"
    out.mkdir()
    entry = batch_run.run_blender_asset(str(source), str(out), _settings(ts, "--ratio", "0.5"), _runner())
    assert entry["output"] == str(out / source.name)
    assert len(entry["objects"]) == 1, [o["object"] for o in entry["objects"]]
    [body] = entry["objects"]
    assert body["vertices_out"] < body["vertices_in"]
    [lod] = body["lods"]
    assert lod["hausdorff"] > 0
    assert not any(p.name.startswith(".topstoc-partial") for p in out.iterdir())

    before = _read_back(ts, source)
    after = _read_back(ts, out / source.name)
    assert after["polygons"] == body["triangles_out"]
    if kind in ("fbx", "usdc"):
        assert len(after["positions"]) == body["vertices_out"]
    assert after["bones"] == before["bones"] == ["Lower", "Upper"]
    assert after["armature"] and before["armature"]
    _assert_follows_the_input(before, after)
    assert sorted(before["keys"]) == ["Bulge"]
    assert sorted(after["keys"]) == ["Bulge"]
    index_in = {_key(p): i for i, p in enumerate(before["positions"])}
    for vertex, position in enumerate(after["positions"]):
        np.testing.assert_allclose(after["keys"]["Bulge"][vertex], before["keys"]["Bulge"][index_in[_key(position)]],
                                   atol=1e-4)


def test_lod_chain_in_one_file_and_one_file_per_lod(ts, scene, tmp_path):
    _character()
    source = tmp_path / "character.glb"
    _export(source, "glb")
    batch_run = importlib.import_module(ts.__name__ + ".core.batch.run")
    out = tmp_path / "one"
    out.mkdir()
    entry = batch_run.run_blender_asset(str(source), str(out), _settings(ts, "--screen-pixels", "150", "50", "15"),
                                        _runner())
    [body] = entry["objects"]
    assert [lod["object"] for lod in body["lods"]] == ["Body_LOD0", "Body_LOD1", "Body_LOD2"]
    counts = [lod["vertices"] for lod in body["lods"]]
    assert counts[0] > counts[1] > counts[2]
    assert all(lod["hausdorff_pixels"] <= 1.0 for lod in body["lods"])
    scene_io = importlib.import_module(ts.__name__ + ".blender.io.scene_files")
    scene_io.import_file(str(out / "character.glb"))
    meshes = {o.name: o for o in bpy.context.scene.objects if o.type == "MESH" and not _is_bone_shape(o)}
    assert sorted(meshes) == ["Body_LOD0", "Body_LOD1", "Body_LOD2"]
    assert [len(meshes[f"Body_LOD{i}"].data.polygons) for i in range(3)] == [lod["triangles"] for lod in body["lods"]]
    assert all(any(m.type == "ARMATURE" for m in o.modifiers) or (o.parent and o.parent.type == "ARMATURE")
               for o in meshes.values())
    # One file per LOD.
    files = tmp_path / "files"
    files.mkdir()
    entry = batch_run.run_blender_asset(str(source), str(files), _settings(ts, "--ratio", "1", "0.3", "--lod-files"),
                                        _runner())
    assert [p.split("/")[-1] for p in entry["outputs"]] == ["character_LOD0.glb", "character_LOD1.glb"]
    for index, path in enumerate(entry["outputs"]):
        scene_io.import_file(path)
        [obj] = [o for o in bpy.context.scene.objects if o.type == "MESH" and not _is_bone_shape(o)]
        assert obj.name == f"Body_LOD{index}"
        assert len(obj.data.polygons) == entry["objects"][0]["lods"][index]["triangles"]
    assert json.dumps(entry)  # the report entry is plain JSON


def test_usd_without_usd_support_is_a_clear_failure(ts, scene, tmp_path):
    if bpy.app.build_options.usd:
        pytest.skip("this Blender has USD")
    source = tmp_path / "asset.usdc"
    source.write_bytes(b"PXR-USDC")
    batch_run = importlib.import_module(ts.__name__ + ".core.batch.run")
    outcome = batch_run.run_asset(str(source), str(tmp_path / "out"), _settings(ts, "--ratio", "0.5"), _runner())
    assert outcome["status"] == "failed"
    assert "built without USD" in outcome["message"], outcome["message"]
