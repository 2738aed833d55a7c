"""An edited mesh file's attributes carried over: UVs, colours, materials and polygons follow
the edit's maps (topology edits and the clean-up write files through this)."""
import numpy as np

from ..api.io import MeshData


def carried_over(data, result):
    """The input's MeshData with the edit applied: attributes follow the result's maps."""
    return MeshData(
        vertices=result.vertices, triangles=result.triangles,
        triangle_polygon=_polygons(data.triangle_polygon, result),
        corner_uvs=None if data.corner_uvs is None else result.corner_attribute(data.corner_uvs),
        vertex_colors=None if data.vertex_colors is None else result.vertex_attribute(data.vertex_colors),
        triangle_material=None if data.triangle_material is None else result.face_attribute(data.triangle_material),
        material_names=data.material_names, material_libraries=data.material_libraries)


def _polygons(triangle_polygon, result) -> np.ndarray:
    """Polygon numbering of the new triangles: a file polygon stays whole while its triangles
    still form the same fan (a cut may separate them); patch triangles are polygons of their own."""
    source = result.face_source
    old = np.where(source >= 0, np.asarray(triangle_polygon)[np.maximum(source, 0)], -1)
    t = result.triangles
    same = np.zeros(len(t), bool)
    if len(t) > 1:
        same[1:] = (old[1:] >= 0) & (old[1:] == old[:-1]) & (t[1:, 0] == t[:-1, 0]) & (t[1:, 1] == t[:-1, 2])
    return (np.cumsum(~same) - 1).astype(np.int32)
