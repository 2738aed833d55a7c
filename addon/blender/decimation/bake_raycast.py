"""A normal-map bake without Cycles, for a Blender whose Cycles bakes nothing selected-to-active
(Debian's Blender 3.4): the same rays as Cycles' bake (from the result's surface pushed out by the
extrusion, inward along its smooth normal, at most the max ray distance; first hit on the source),
cast with Blender's BVH tree, and the source's smooth normal at the hit written in the result's
MikkTSpace tangent frame (what the Normal Map node reads back). Texel centres only, no antialiasing.
The bake is a generator yielding after every chunk of rays (drive runs one to its end with a
progress callback whose False cancels: the image is left as it was)."""

from __future__ import annotations

import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

from ...core.carry.normal_bake import dilate, rasterize
from ...core.support.errors import TopStocError

CHUNK = 8192  #: rays cast between two progress reports


class Cancelled(TopStocError):
    """The progress callback asked the ray cast to stop."""


def _corner_normals(mesh) -> np.ndarray:
    if hasattr(mesh, "corner_normals"):  # Blender 4.1+
        normals = np.empty(3 * len(mesh.loops), dtype=np.float32)
        mesh.corner_normals.foreach_get("vector", normals)
        return normals.reshape(-1, 3).astype(np.float64)
    mesh.calc_normals_split()
    normals = np.empty(3 * len(mesh.loops), dtype=np.float32)
    mesh.loops.foreach_get("normal", normals)
    return normals.reshape(-1, 3).astype(np.float64)


def _triangles(mesh) -> tuple:
    """(loop ids (m, 3), vertex ids (m, 3)) of the loop triangles."""
    mesh.calc_loop_triangles()
    loops = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    vertices = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", vertices)
    return loops.reshape(-1, 3), vertices.reshape(-1, 3)


def _world(mesh, matrix) -> np.ndarray:
    co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def _unit(vectors: np.ndarray) -> np.ndarray:
    return vectors / np.maximum(np.linalg.norm(vectors, axis=-1, keepdims=True), 1e-30)


def _tangent_frames(mesh, uv_map: str, rotation: np.ndarray) -> tuple:
    """Per corner: world normal, tangent and bitangent sign (MikkTSpace on ``uv_map``)."""
    normals = _unit(_corner_normals(mesh) @ np.linalg.inv(rotation))
    mesh.calc_tangents(uvmap=uv_map)
    tangents = np.empty(3 * len(mesh.loops), dtype=np.float32)
    mesh.loops.foreach_get("tangent", tangents)
    signs = np.empty(len(mesh.loops), dtype=np.float32)
    mesh.loops.foreach_get("bitangent_sign", signs)
    return normals, _unit(tangents.reshape(-1, 3) @ rotation.T), signs


def _frames(normal, tangent, sign) -> np.ndarray:
    """(k, 3, 3) columns tangent, bitangent, normal, interpolated and not normalised: the frame
    the Normal Map node decodes with (colour x T + y B + z N), B = sign N x T."""
    return np.stack([tangent, sign[:, None] * np.cross(normal, tangent), normal], axis=2)


def _encode(frames, normals) -> np.ndarray:
    """The unit tangent-space vectors the frames decode into ``normals``, as Blender's bake
    writes them (the frame inverted, not assumed orthonormal); (0, 0, 1) in a degenerate frame."""
    encoded = np.tile((0.0, 0.0, 1.0), (len(normals), 1))
    good = np.abs(np.linalg.det(frames)) > 1e-9
    encoded[good] = np.linalg.solve(frames[good], normals[good][:, :, None])[:, :, 0]
    return _unit(encoded)


def _source_normals(mesh, matrix, hits, triangle_ids) -> np.ndarray:
    """The source's smooth (corner) normal at each hit point of its loop triangles."""
    loops, vertices = _triangles(mesh)
    normals = _unit(_corner_normals(mesh) @ np.linalg.inv(matrix[:3, :3]))
    corners = _world(mesh, matrix)[vertices[triangle_ids]]        # (k, 3, 3)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    area = np.cross(b - a, c - a)
    weights = np.stack([np.einsum("ij,ij->i", np.cross(c - b, hits - b), area),
                        np.einsum("ij,ij->i", np.cross(a - c, hits - c), area),
                        np.einsum("ij,ij->i", np.cross(b - a, hits - a), area)], axis=1)
    weights /= np.maximum(weights.sum(axis=1, keepdims=True), 1e-30)
    return _unit(np.einsum("ij,ijk->ik", weights, normals[loops[triangle_ids]]))


def _cast(tree, origins, directions, reach):
    """Yields the fraction cast after every CHUNK rays; returns (hit locations, triangle ids,
    whether hit) of the first hits within ``reach``."""
    hits = np.zeros_like(origins)
    ids = np.zeros(len(origins), dtype=np.int64)
    found = np.zeros(len(origins), dtype=bool)
    for start in range(0, len(origins), CHUNK):
        stop = min(start + CHUNK, len(origins))
        for i, origin, direction in zip(range(start, stop), origins[start:stop].tolist(),
                                        directions[start:stop].tolist()):
            location, _normal, index, _distance = tree.ray_cast(Vector(origin), Vector(direction), reach)
            if index is not None:
                hits[i], ids[i], found[i] = location, index, True
        yield stop / len(origins)
    return hits, ids, found


def drive(steps, progress=None):
    """Runs the generator ``steps`` to its end, telling ``progress`` every fraction it yields;
    progress's False closes it (its own clean-up runs) and raises Cancelled. Returns its value."""
    while True:
        try:
            fraction = next(steps)
        except StopIteration as done:
            return done.value
        if progress is not None and progress(fraction) is False:
            steps.close()
            raise Cancelled("normal map bake cancelled")


def bake_steps(source, result, image, uv_map: str, extrusion: float, max_ray: float, margin: int):
    """Writes the tangent-space normals of ``source`` seen from ``result`` (placed where the source
    is) into ``image`` (square), laid out on ``uv_map``, with ``margin`` texels of bleed, yielding
    the fraction of rays cast after every chunk (``image`` is written after the last)."""
    size = image.size[0]
    matrix = np.array(source.matrix_world, dtype=np.float64)
    mesh = result.data
    loops, vertices = _triangles(mesh)
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    mesh.uv_layers[uv_map].data.foreach_get("uv", uv)
    texels, triangle, weights = rasterize(uv.reshape(-1, 2)[loops], size)
    normals, tangents, signs = _tangent_frames(mesh, uv_map, matrix[:3, :3])
    corner = loops[triangle]                                      # (k, 3) loops of each texel's triangle
    points = np.einsum("ij,ijk->ik", weights, _world(mesh, matrix)[vertices[triangle]])
    normal = np.einsum("ij,ijk->ik", weights, normals[corner])
    frames = _frames(normal, np.einsum("ij,ijk->ik", weights, tangents[corner]), signs[corner[:, 0]])
    normal = _unit(normal)

    _, source_vertices = _triangles(source.data)
    tree = BVHTree.FromPolygons(_world(source.data, matrix).tolist(), source_vertices.tolist())
    hits, ids, found = yield from _cast(tree, points + extrusion * normal, -normal, max_ray)
    seen = normal.copy()
    seen[found] = _source_normals(source.data, matrix, hits[found], ids[found])
    encoded = _encode(frames, seen)

    values = np.zeros((size * size, 3))
    values[texels] = encoded * 0.5 + 0.5
    filled = np.zeros(size * size, dtype=bool)
    filled[texels] = True
    values, filled = values.reshape(size, size, 3), filled.reshape(size, size)
    dilate(values, filled, margin)
    values[~filled] = (0.5, 0.5, 1.0)
    pixels = np.concatenate([values, np.ones((size, size, 1))], axis=2).astype(np.float32)
    image.pixels.foreach_set(pixels.ravel())
    image.update()
