"""Writing a triangle mesh into Blender (mesh_write.fill_geometry, the Live Preview's frames and every
result's geometry): what Blender's per-element accessors read back is the mesh written, whichever
way it went in (Blender 3.0-3.5: straight into the MLoop, MPoly and MEdge arrays, dna_arrays;
later versions: attributes and foreach_set)."""

import bpy
import numpy as np

import meshgen


def test_geometry_written_is_what_blender_reads_back(ts, scene, monkeypatch):
    mesh_write, dna = ts.blender.io.mesh_write, ts.blender.io.dna_arrays
    vertices, triangles = meshgen.torus(48, 24)
    triangles = np.asarray(triangles)
    edges = ts.core.mesh_edges(triangles, len(vertices))
    used = {}
    write = dna.write_field

    def recorded(collection, prop, values):
        used[prop] = write(collection, prop, values)
        return used[prop]
    monkeypatch.setattr(dna, "write_field", recorded)
    mesh = bpy.data.meshes.new("Written")
    mesh_write.fill_geometry(mesh, vertices, triangles, edges)
    legacy = (3, 0, 0) <= bpy.app.version < (3, 6, 0)  # these Blenders keep MLoop / MPoly / MEdge arrays
    assert used == dict.fromkeys(used, legacy) and len(used) == (5 if legacy else 1)  # 4.x: loop_start only
    np.testing.assert_array_equal([loop.vertex_index for loop in mesh.loops], triangles.ravel())
    np.testing.assert_array_equal([loop.edge_index for loop in mesh.loops], edges.corner_edge.ravel())
    np.testing.assert_array_equal([p.loop_start for p in mesh.polygons], np.arange(0, 3 * len(triangles), 3))
    assert {p.loop_total for p in mesh.polygons} == {3}
    np.testing.assert_array_equal([tuple(e.vertices) for e in mesh.edges], edges.vertices)
    np.testing.assert_allclose([v.co[:] for v in mesh.vertices], vertices, rtol=1e-6)
    assert not any(e.use_seam or e.use_edge_sharp or getattr(e, "crease", 0) for e in mesh.edges)  # untouched: 0
    assert not mesh.validate(verbose=False)  # nothing for Blender to repair
    assert dna._probed_view(mesh.loops, dna.MEDGE, "v", "vertices") is None  # another size is refused
