// Topological invariants of a simplicial complex, per connected component (docs/design.md §4.1,
// thesis 3.1 and 4.2.1), for any triangle mesh: several components, open or closed,
// orientable or not, manifold or not, with wire edges and isolated vertices.
//
// Homology is over Z2. For every component beta0 = 1 and, by Euler-Poincare,
// beta1 = beta0 + beta2 - euler, so everything rests on beta2 = dim ker d2:
//  - triangles joined across edges with exactly two triangles form "sheets"; a 2-cycle takes a
//    sheet whole or not at all, and never a sheet with a boundary edge (one triangle);
//  - without edges of three or more triangles, beta2 is the number of sheets with no boundary
//    edge (linear time);
//  - with such edges, each one asks that the sheets around it be taken an even number of
//    times: beta2 = free sheets - rank of that Z2 system, reduced with PHAT (only there).
// Orientability comes from the same pass (a parity union-find over triangles), manifoldness from
// the fan around each vertex, boundary loops from walking boundary edges around those fans.
//
// Everything is reported in the caller's vertex ids.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/topology/complex.hpp"

namespace topstoc {

enum class ComponentKind : int8_t {
  vertex = 0,   ///< an isolated vertex
  graph = 1,    ///< edges, no triangle
  surface = 2,  ///< at least one triangle (possibly with wire edges attached)
};

/// -1 where a property is not defined (e.g. orientability next to an edge of three triangles).
struct ComponentTopology {
  ComponentKind kind = ComponentKind::vertex;
  int32_t first_vertex = 0;  ///< smallest vertex id; components are numbered in this order
  int32_t vertices = 0, edges = 0, triangles = 0;
  int64_t euler = 0;  ///< vertices - edges + triangles
  int32_t betti[3] = {1, 0, 0};
  int32_t boundary_edges = 0;     ///< edges with one triangle
  int32_t nonmanifold_edges = 0;  ///< surface only: edges with no triangle or three and more
  int32_t nonmanifold_vertices = 0;
  int32_t boundary_loops = 0;  ///< closed boundary curves
  int32_t boundary_paths = 0;  ///< open boundary curves (they end at non-manifold edges)
  int8_t closed = -1;          ///< surface: no boundary edge
  int8_t manifold = -1;        ///< surface: every edge has 1 or 2 triangles, every vertex one fan
  int8_t orientable = -1;      ///< surface without edges of 3+ triangles: triangles can be oriented consistently
  int8_t consistently_oriented = -1;  ///< surface: the given corner orders agree across every shared edge
  int32_t genus = -1;          ///< orientable manifold: (2 - euler - boundary_loops) / 2
  int32_t crosscaps = -1;      ///< non-orientable manifold: 2 - euler - boundary_loops
};

struct TopologyReport {
  int32_t betti[3] = {0, 0, 0};
  int32_t num_vertices = 0, num_edges = 0, num_triangles = 0;
  int32_t collapsed_triangles = 0, duplicate_triangles = 0;
  std::vector<ComponentTopology> components;
  /// Component of each vertex.
  std::vector<int32_t> vertex_component;
  /// Boundary curves (CSR): curve i visits boundary_vertices[boundary_offsets[i] ..
  /// boundary_offsets[i+1]); a closed curve does not repeat its first vertex; the first edge
  /// follows the corner order of its triangle.
  std::vector<int32_t> boundary_offsets = {0};
  std::vector<int32_t> boundary_vertices;
  std::vector<int32_t> boundary_component;
  std::vector<uint8_t> boundary_closed;
  /// Non-manifold edges (vertex pairs, lower first) with their number of triangles, and
  /// non-manifold vertices, in increasing order; only in surface components.
  std::vector<int32_t> nonmanifold_edges;
  std::vector<int32_t> nonmanifold_edge_triangles;
  std::vector<int32_t> nonmanifold_vertices;
};

/// Invariants of the complex, per component and in total.
TopologyReport analyze_topology(const SimplicialComplex& complex);

/// Convenience: builds the complex from the caller's arrays (see build_complex) and analyses it.
TopologyReport analyze_topology(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                int64_t num_triangles, const int32_t* edges, int64_t num_edges);

}  // namespace topstoc
