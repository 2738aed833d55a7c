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
//
// Sides: side s = 3t + c of triangle t runs from corner c to corner c+1. Walking around a
// vertex only needs, per side, the side across its edge (side_twin), so the walks touch one
// array: that is what keeps them fast on meshes whose vertex order has no locality.
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
  /// Number of triangles on each edge (0 for a wire edge, 1 on a boundary, 2 inside a surface).
  std::vector<int32_t> edge_triangles;
  /// triangle_edges[s]: the edge of side s.
  std::vector<int32_t> triangle_edges;
  /// side_twin[s]: when the edge of s has exactly two triangles, 2 * (the other side) + 1 if both
  /// sides run along the edge in the same direction (inconsistent orientation), + 0 otherwise;
  /// kOpenSide when s is the edge's only side, kFinSide when the edge has three or more.
  std::vector<int32_t> side_twin;
  static constexpr int32_t kOpenSide = -1;
  static constexpr int32_t kFinSide = -2;
  /// Triangles at each vertex, and one side starting at it (-1 for none).
  std::vector<int32_t> vertex_triangles;
  std::vector<int32_t> vertex_side;

  int32_t input_triangles = 0;
  int32_t input_edges = 0;
  /// Triangles with a repeated vertex (read as an edge or a vertex).
  int32_t collapsed_triangles = 0;
  /// Triangles with the vertex set of an earlier triangle (the same simplex again).
  int32_t duplicate_triangles = 0;

  int32_t num_triangles() const { return static_cast<int32_t>(triangles.size() / 3); }
  int32_t num_edges() const { return static_cast<int32_t>(edges.size() / 2); }
  /// Vertex where side s starts, and where it ends.
  int32_t side_start(int32_t s) const { return triangles[s]; }
  int32_t side_end(int32_t s) const { return triangles[next_side(s)]; }
  static int32_t next_side(int32_t s) { return s - s % 3 + (s % 3 + 1) % 3; }
  static int32_t previous_side(int32_t s) { return s - s % 3 + (s % 3 + 2) % 3; }
};

/// Builds the complex. positions: 3 * num_vertices coordinates, checked to be finite (may be
/// null to skip the check); triangles: 3 * num_triangles vertex ids; edges: 2 * num_edges vertex
/// ids (may be null when num_edges is 0). At most 2^30 / 3 (about 357 million) triangles.
/// Throws std::invalid_argument naming the first offending vertex, triangle or edge.
SimplicialComplex build_complex(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges);

/// Vertex-to-edge incidence (CSR): the edges of vertex v are
/// incident_edges[offsets[v] .. offsets[v+1]), in increasing edge order.
void vertex_edges(const SimplicialComplex& complex, std::vector<int32_t>& offsets, std::vector<int32_t>& incident_edges);

/// Turning around a vertex v through the triangle sides that touch it. A position is a side x
/// of a triangle at v and whether v is where x starts. Orientation-free: works on
/// inconsistently oriented and non-orientable surfaces.
struct FanCursor {
  int32_t side;
  bool starts_at_vertex;

  /// The other side of the same triangle at v.
  void turn() {
    side = starts_at_vertex ? SimplicialComplex::previous_side(side) : SimplicialComplex::next_side(side);
    starts_at_vertex = !starts_at_vertex;
  }
  /// Steps across the edge of the current side into the neighbouring triangle. Returns false
  /// (and stays) when the edge does not have exactly two triangles.
  bool cross(const SimplicialComplex& complex) {
    const int32_t code = complex.side_twin[side];
    if (code < 0) return false;
    side = code >> 1;
    if (!(code & 1)) starts_at_vertex = !starts_at_vertex;  // opposite directions: roles swap
    return true;
  }
};

}  // namespace topstoc
