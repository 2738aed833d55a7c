// The simplicial complex spanned by a caller's vertex, triangle and edge arrays.
//
// Topology works on this rather than on topstoc::Mesh: Mesh prepares a surface for decimation
// (it drops degenerate and duplicate triangles and renumbers vertices), whereas invariants must
// describe exactly the complex the caller's arrays describe, in the caller's vertex ids:
//  - every vertex 0..n-1 is a 0-simplex, also one that no triangle or edge uses (an isolated
//    vertex is a component of its own);
//  - a triangle with three distinct vertices is a 2-simplex; further triangles with the same
//    vertex set (in any order or orientation) are the same simplex, counted once ("duplicates");
//  - a triangle with exactly two distinct vertices is read as the edge between them, one with a
//    single distinct vertex as that vertex ("collapsed" triangles): nothing they span is lost;
//  - extra edges (a, b), a != b, are 1-simplices (wire edges, bare edge graphs); (a, a) is the
//    vertex a.
// Out-of-range indices and non-finite coordinates raise std::invalid_argument naming the element.
// The caller's arrays are only read.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

struct SimplicialComplex {
  int32_t num_vertices = 0;
  /// Distinct 2-simplices: three corners each, in the caller's corner order (orientation of the
  /// first occurrence), and the index of that occurrence in the caller's triangle array.
  std::vector<int32_t> triangles;
  std::vector<int32_t> triangle_source;
  /// Distinct 1-simplices as (lower, higher) vertex pairs, sorted lexicographically.
  std::vector<int32_t> edges;
  /// triangle_edges[3t + c] is the edge from corner c to corner c+1 of triangle t.
  std::vector<int32_t> triangle_edges;
  /// Triangle sides on each edge (CSR): edge_sides[edge_side_offsets[e] .. edge_side_offsets[e+1])
  /// lists sides 3t + c, in increasing order, whose edge is e.
  std::vector<int32_t> edge_side_offsets;
  std::vector<int32_t> edge_sides;

  int32_t input_triangles = 0;
  int32_t input_edges = 0;
  /// Triangles with a repeated vertex (read as an edge or a vertex).
  int32_t collapsed_triangles = 0;
  /// Triangles with the vertex set of an earlier triangle (the same simplex again).
  int32_t duplicate_triangles = 0;

  int32_t num_triangles() const { return static_cast<int32_t>(triangles.size() / 3); }
  int32_t num_edges() const { return static_cast<int32_t>(edges.size() / 2); }
  /// Number of triangles on edge e (0 for a wire edge, 1 on a boundary, 2 inside a surface).
  int32_t edge_triangle_count(int32_t e) const { return edge_side_offsets[e + 1] - edge_side_offsets[e]; }
  /// The vertex opposite side s (the third corner of its triangle).
  int32_t opposite(int32_t side) const { return triangles[3 * (side / 3) + (side % 3 + 2) % 3]; }
};

/// Builds the complex. positions: 3 * num_vertices coordinates, checked to be finite (may be
/// null to skip the check); triangles: 3 * num_triangles vertex ids; edges: 2 * num_edges vertex
/// ids (may be null when num_edges is 0). Throws std::invalid_argument naming the first
/// offending vertex, triangle or edge.
SimplicialComplex build_complex(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges);

/// Vertex-to-edge incidence (CSR): the edges of vertex v are
/// incident_edges[offsets[v] .. offsets[v+1]), in increasing edge order.
void vertex_edges(const SimplicialComplex& complex, std::vector<int32_t>& offsets, std::vector<int32_t>& incident_edges);

}  // namespace topstoc
