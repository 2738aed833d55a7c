// One closed, manifold component of a Mesh with compact local ids: the shape that every
// handle/tunnel loop algorithm (tetrahedralize, persistence, homology, loop selection,
// shortening) works on.
//
// Local vertex, edge and face ids run from 0; mesh_vertex maps a local vertex back to the
// Mesh's internal id (and Mesh::vertex_source() from there to the caller's id). Arrays are
// sized by the component, so analysing a small torus inside a huge scan costs little.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc {

struct ClosedSurface {
  std::vector<double> positions;          ///< 3 per local vertex
  std::vector<int32_t> triangles;         ///< 3 local vertex ids per face, as oriented in the mesh
  std::vector<int32_t> edge_vertices;     ///< 2 local vertex ids per edge, lower first
  std::vector<int32_t> edge_faces;        ///< the 2 faces of each edge
  std::vector<int32_t> face_edges;        ///< 3 per face: edge from corner c to corner c + 1
  std::vector<int32_t> adjacency_offsets; ///< vertex adjacency, CSR
  std::vector<int32_t> adjacency;         ///< neighbour of each slot
  std::vector<int32_t> adjacency_edge;    ///< edge of each slot
  std::vector<int32_t> mesh_vertex;       ///< Mesh internal id of each local vertex

  int32_t num_vertices() const { return int32_t(mesh_vertex.size()); }
  int32_t num_edges() const { return int32_t(edge_vertices.size() / 2); }
  int32_t num_faces() const { return int32_t(triangles.size() / 3); }
  int64_t euler() const { return int64_t(num_vertices()) - num_edges() + num_faces(); }
  /// Genus of the closed orientable surface: chi = 2 - 2g.
  int32_t genus() const { return int32_t((2 - euler()) / 2); }
  const double* position(int32_t v) const { return &positions[3 * size_t(v)]; }
  double edge_length(int32_t e) const;
  /// Edge between local vertices a and b, or -1.
  int32_t find_edge(int32_t a, int32_t b) const;
};

/// What a component is, for the purpose of handle and tunnel loops.
struct SurfaceCheck {
  std::string problem;  ///< "" (closed orientable manifold), "open", "non-manifold" or "non-orientable"
  std::string detail;   ///< one sentence naming an offending element (caller's vertex ids)
  int32_t vertices = 0, edges = 0, faces = 0;
  int32_t boundary_edges = 0;
  int32_t boundary_loops = 0;  ///< cycles of boundary edges (manifold components)
  int32_t nonmanifold_edges = 0;
  int32_t pinched_vertices = 0;
  int32_t first_vertex = 0;  ///< smallest caller vertex id in the component

  int64_t euler() const { return int64_t(vertices) - edges + faces; }
  /// chi = 2 - 2g - b for an orientable manifold surface; -1 when that does not apply.
  int32_t genus() const {
    return problem.empty() || problem == "open" ? int32_t((2 - euler() - boundary_loops) / 2) : -1;
  }
};

/// Vertices (internal ids, increasing) of each component of `mesh`.
std::vector<std::vector<int32_t>> component_vertices(const Mesh& mesh);

/// Checks every component of `mesh`: closed, manifold (no edge with three or more triangles, no
/// pinched vertex) and orientable. Indexed by Mesh component id.
std::vector<SurfaceCheck> check_closed_surfaces(const Mesh& mesh, const std::vector<std::vector<int32_t>>& components);

/// Extracts the component made of `vertices` (internal ids; it must pass the check).
ClosedSurface extract_surface(const Mesh& mesh, const std::vector<int32_t>& vertices);

}  // namespace topstoc
