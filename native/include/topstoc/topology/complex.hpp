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
// Internal numbering, for memory locality: the caller's numbering is kept when triangles
// already span nearby vertex ids; when the triangle order is coherent (consecutive triangles
// close together) but the ids are scattered, vertices are numbered by first appearance in it
// (Loop-subdivided meshes such as turbine x3); otherwise
// (shuffled meshes) vertices follow a Z-order (Morton) curve of
// their positions and triangles are sorted by lowest vertex, which halves the analysis time
// there. Every vertex id inside the struct is internal; vertex_source maps back to the caller's
// ids, vertex_index maps the caller's ids in. Results handed to callers use the caller's ids.
//
// Sides instead of an edge table: side s = 3t + c of triangle t runs from corner c to corner
// c+1. Each side records the side across its edge (side_twin), which is all that walking around
// vertices, grouping triangles and building trees needs; edges with no triangle or with three
// or more are listed apart (they are rare). Keeping one int per side and no edge ids halves the
// memory the analysis touches, which is what its time depends on for large meshes whose vertex
// order has no locality.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

/// Passes over fewer items than this stay serial: starting threads costs more than it saves
/// (and much more when the machine is busy and a thread waits to be scheduled).
inline constexpr int64_t kParallelMinimum = 1 << 17;

struct SimplicialComplex {
  static constexpr int32_t kOpenSide = -1;  ///< the edge has this triangle only (a boundary edge)
  static constexpr int32_t kFinSide = -2;   ///< the edge has three or more triangles

  int32_t num_vertices = 0;
  /// Caller's id of each internal vertex, and internal id of each caller vertex.
  std::vector<int32_t> vertex_source;
  std::vector<int32_t> vertex_index;
  /// Distinct 2-simplices (internal vertex ids): three corners each, in the caller's corner
  /// order (orientation of the first occurrence), and the index of that occurrence in the
  /// caller's triangle array.
  std::vector<int32_t> triangles;
  std::vector<int32_t> triangle_source;
  /// side_twin[s]: when the edge of s has exactly two triangles, 2 * (the other side) + 1 if both
  /// sides run along the edge in the same direction (inconsistent orientation), + 0 otherwise;
  /// kOpenSide or kFinSide otherwise.
  std::vector<int32_t> side_twin;
  /// Triangles at each vertex, and one side starting at it (-1 for none).
  std::vector<int32_t> vertex_triangles;
  std::vector<int32_t> vertex_side;
  /// The sides starting at each vertex, in side order (CSR: vertex_star[vertex_star_offsets[v]
  /// .. vertex_star_offsets[v+1])). On a closed manifold their ends are v's neighbours, once each.
  std::vector<int32_t> vertex_star;
  std::vector<int32_t> vertex_star_offsets;
  /// Edges with three or more triangles (internal vertex pairs, lower first, sorted) and their sides
  /// (CSR: fin_sides[fin_offsets[i] .. fin_offsets[i+1]), increasing).
  std::vector<int32_t> fin_edges;
  std::vector<int32_t> fin_offsets = {0};
  std::vector<int32_t> fin_sides;
  /// Edges in no triangle (internal vertex pairs, lower first, sorted).
  std::vector<int32_t> wire_edges;
  /// Number of distinct edges (1-simplices) of the complex.
  int32_t num_edges = 0;

  int32_t input_triangles = 0;
  int32_t input_edges = 0;
  /// Triangles with a repeated vertex (read as an edge or a vertex).
  int32_t collapsed_triangles = 0;
  /// Triangles with the vertex set of an earlier triangle (the same simplex again).
  int32_t duplicate_triangles = 0;

  /// Working memory of build_complex, kept here so that building into the same object again
  /// reuses it (see build_complex).
  struct Scratch {
    std::vector<int32_t> histograms;
  } scratch;

  int32_t num_triangles() const { return static_cast<int32_t>(triangles.size() / 3); }
  int32_t num_sides() const { return static_cast<int32_t>(triangles.size()); }
  /// Vertex where side s starts, and where it ends.
  int32_t side_start(int32_t s) const { return triangles[s]; }
  int32_t side_end(int32_t s) const { return triangles[next_side(s)]; }
  static int32_t next_side(int32_t s) { return s % 3 == 2 ? s - 2 : s + 1; }
  static int32_t previous_side(int32_t s) { return s % 3 == 0 ? s + 2 : s - 1; }
  /// True for exactly one side of every edge with one or two triangles (the edge's
  /// representative side): open sides, and the lower side of each twin pair.
  bool represents_edge(int32_t s) const { return side_twin[s] == kOpenSide || (side_twin[s] >> 1) > s; }
};

/// Builds the complex. positions: 3 * num_vertices coordinates, checked to be finite and used
/// for the internal order (may be null: no check, no Z-order); triangles: 3 * num_triangles
/// vertex ids; edges: 2 * num_edges vertex ids (may be null when num_edges is 0). The arrays
/// are only read. At most 2^30 / 3 (about 357 million) triangles. Throws
/// std::invalid_argument naming the first offending vertex, triangle or edge.
SimplicialComplex build_complex(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges);

/// Same, into `out`, whose vectors keep the memory they already hold: callers that analyse
/// mesh after mesh keep one complex around, since fresh pages (page faults and zeroing by the
/// kernel) cost about as much as the work done on them.
void build_complex(SimplicialComplex& out, const double* positions, int32_t num_vertices, const int32_t* triangles,
                   int64_t num_triangles, const int32_t* edges, int64_t num_edges);

/// Turning around a vertex v through the triangle sides that touch it. A position is a side of
/// a triangle at v and whether v is where that side starts. Orientation-free: works on
/// inconsistently oriented and non-orientable surfaces.
struct FanCursor {
  int32_t side;
  bool starts_at_vertex;

  /// The vertex at the other end of the current side.
  int32_t neighbour(const SimplicialComplex& k) const {
    return starts_at_vertex ? k.side_end(side) : k.side_start(side);
  }
  /// The other side of the same triangle at v.
  void turn() {
    side = starts_at_vertex ? SimplicialComplex::previous_side(side) : SimplicialComplex::next_side(side);
    starts_at_vertex = !starts_at_vertex;
  }
  /// Steps across the edge of the current side into the neighbouring triangle. Returns false
  /// (and stays) when the edge does not have exactly two triangles.
  bool cross(const SimplicialComplex& k) {
    const int32_t code = k.side_twin[side];
    if (code < 0) return false;
    side = code >> 1;
    if (!(code & 1)) starts_at_vertex = !starts_at_vertex;  // opposite directions: roles swap
    return true;
  }
};

}  // namespace topstoc
