// The edges of a triangle list and the edge of every corner: what a host application (Blender's
// edge and loop arrays) needs to store a triangle mesh without deriving its edges itself. A
// separate concept from decimation: any triangle list goes in, the result is not touched.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

struct MeshEdges {
  /// 2 per edge, lower vertex id first, each edge once. Edges are ordered by lower vertex, then
  /// by the first corner that uses them.
  std::vector<int32_t> vertices;
  /// 3 per triangle: the edge from corner k to corner k + 1 (mod 3) of that triangle, as Blender
  /// pairs a loop with the edge to the next loop of its face.
  std::vector<int32_t> corner_edge;
};

/// Edges of `num_triangles` triangles over `num_vertices` vertices. The result depends only on
/// the triangles (not on the number of threads). Throws std::invalid_argument on an index out
/// of range or a triangle that repeats a vertex (it would need an edge from a vertex to itself).
MeshEdges mesh_edges(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices);

}  // namespace topstoc
