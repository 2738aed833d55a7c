"""Vertex and triangle counts of anything that holds a mesh as ``vertices`` and ``triangles`` arrays."""


class MeshCounts:
    """``num_vertices`` and ``num_triangles`` from the ``vertices`` and ``triangles`` arrays."""

    @property
    def num_vertices(self) -> int:
        return len(self.vertices)

    @property
    def num_triangles(self) -> int:
        return len(self.triangles)
