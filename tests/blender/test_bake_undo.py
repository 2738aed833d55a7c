"""One undo after Guided Decimate (or the LOD chain) with Bake Normals brings the file back as it
was: no result object, no material copy, no baked image, no orphan mesh; the source's mesh and
materials (their nodes) unchanged. Redo bakes again."""

import bpy
import pytest

from helpers import select_only, snapshot
from test_bake_normals import normal_map_image, small_pair


def datablocks():
    """The names of everything a bake can add, by kind."""
    return {kind: sorted(item.name for item in getattr(bpy.data, kind))
            for kind in ("objects", "meshes", "materials", "images", "node_groups", "textures")}


def material_nodes(obj):
    return [(m.name, sorted(node.bl_idname for node in m.node_tree.nodes)) for m in obj.data.materials]


RUNS = {"guided_decimate": {"ratio": 0.2}, "lod_chain": {"ratios": "1.0, 0.2"}}


@pytest.mark.parametrize("operator", sorted(RUNS))
def test_one_undo_removes_everything_the_bake_made(ts, scene, operator):
    source = small_pair("pebble")
    name = source.name
    select_only(source)
    bpy.ops.ed.undo_push(message="before")
    before = datablocks(), snapshot(source.data), material_nodes(source)
    result = getattr(bpy.ops.topstoc, operator)("EXEC_DEFAULT", True, bake_normals=True, bake_size="256",
                                                bake_margin=2, **RUNS[operator])  # True: push undo
    assert result == {"FINISHED"}
    made = datablocks()
    baked = [obj for obj in bpy.data.objects if obj.name != name]
    assert baked and all(normal_map_image(obj) is not None for obj in baked)
    assert len(made["images"]) == len(before[0]["images"]) + len(baked)
    assert any(m.endswith("_TopStoc") for m in made["materials"])
    bpy.ops.ed.undo()
    source = bpy.data.objects[name]                               # undo replaces Python references
    assert (datablocks(), snapshot(source.data), material_nodes(source)) == before
    assert normal_map_image(source) is None
    bpy.ops.ed.redo()
    assert datablocks() == made
