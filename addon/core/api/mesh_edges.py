"""The edges of a triangle list and the edge of every triangle corner.

What a host that stores edges and corners apart (Blender's ``Mesh.edges`` and ``Mesh.loops``)
needs to take a triangle mesh without deriving the edges itself:

>>> edges = mesh_edges(triangles, num_vertices=len(vertices))
>>> edges.vertices      # (k, 2) int32: each edge once, lower id first
>>> edges.corner_edge   # (m, 3) int32: edge from corner j of triangle i to corner j + 1 (mod 3)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..support.native import engine


@dataclass(frozen=True)
class MeshEdges:
    #: (k, 2) int32 vertex pairs, lower id first; ordered by lower vertex, then by first corner
    vertices: np.ndarray
    corner_edge: np.ndarray  #: (m, 3) int32 edge of each corner (to the next corner of its triangle)

    def __len__(self) -> int:
        return len(self.vertices)


def mesh_edges(triangles, num_vertices: int) -> MeshEdges:
    """Edges of ``triangles`` ((m, 3) integer array) over ``num_vertices`` vertices.

    Deterministic (independent of the thread count). Raises ValueError when a triangle holds
    an index outside [0, num_vertices) or repeats a vertex.
    """
    vertices, corner_edge = engine.mesh_edges(triangles, int(num_vertices))
    return MeshEdges(vertices, corner_edge)
