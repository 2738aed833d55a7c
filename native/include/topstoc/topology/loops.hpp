// Handle and tunnel loops of every closed, orientable, manifold component (docs/design.md §4.3; thesis
// 3.2.2-3.2.4, 4.2.1, 5.2.2; Dey, Li, Sun 2007).
//
// A loop on a closed surface in R^3 is a handle loop when it bounds inside the solid (it is
// null-homologous in the inside) but not outside, a tunnel loop when the reverse holds. A
// genus-g surface has g independent loops of each kind; together they span H1 of the surface.
//
// Per component:
//   1. tetrahedralize the inside and the outside (TetGen, surface kept) - on the component
//      itself, or for large components on a coarse TopStoc decimation of it (thesis 5.2.2);
//   2. pair simplices in the order surface < inside < outside (PHAT): g handle and g tunnel
//      cycles with their generator edges;
//   3. pick g short simple handle loops and g tunnel loops spanning the same subspaces;
//   4. on the coarse route, carry each loop back through the decimation's clusters;
//   5. shorten each loop on the full surface without changing its homotopy class.
// Every result is checked before it is returned: each loop is a simple closed cycle of mesh
// edges, the 2g loops span H1 of the full surface, and shortening kept each loop's class and
// never made it longer. A failed check throws std::logic_error instead of returning a wrong
// answer.
//
// Errors (std::invalid_argument): a component that is not manifold or not orientable, or that
// TetGen refuses (self-intersections and the like). Open components are reported, not refused:
// handle and tunnel loops are defined for closed surfaces only.
//
// Caveat of the coarse route: loops are classified on the coarse surface. The decimation keeps
// the topology of the surface; handle or tunnel depends also on how it sits in space, which a
// coarse version close to the original keeps. The benchmark checks this against the full
// tetrahedralization; set coarse_vertices = 0 to always work on the full surface.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/core/progress.hpp"

namespace topstoc {

struct LoopParams {
  /// Vertices of the coarse decimation (whole mesh): -1 automatic (components with more than
  /// full_route_faces triangles go coarse), 0 never coarse, > 0 this target for every component.
  int32_t coarse_vertices = -1;
  int32_t full_route_faces = 20000;
  /// Components larger than this are never tetrahedralized whole, even when the coarse route fails.
  int32_t max_full_faces = 400000;
  bool shorten = true;
  bool count_edges = false;  ///< select and shorten by edge count (the thesis' metric) instead of length
  int32_t max_roots = 0;     ///< shortest-path trees for loop selection (0: automatic)
  uint64_t seed = 1;         ///< decimation seed of the coarse route
  ProgressCallback progress;
};

struct HandleTunnelLoop {
  bool handle = false;
  std::vector<int32_t> vertices;     ///< caller's vertex ids, a simple closed edge cycle (last joins first)
  int32_t generator[2] = {-1, -1};   ///< caller's vertex ids of the generator edge paired with it
  double length = 0.0;               ///< Euclidean length
  double initial_length = 0.0;       ///< before shortening
  std::vector<int32_t> initial_vertices;  ///< the loop before shortening (caller's ids)
};

struct ComponentLoops {
  int32_t first_vertex = 0;     ///< smallest caller vertex id: components are listed in this order
  int32_t vertices = 0, edges = 0, faces = 0;
  int32_t boundary_loops = 0;
  int32_t genus = 0;
  std::string status;           ///< "ok", or "open" (no loops: they need a closed surface)
  std::string detail;
  std::string route;            ///< "full", "coarse" or "" (nothing to compute)
  int32_t analysed_vertices = 0;  ///< vertices of the surface that was tetrahedralized
  int32_t tetrahedra = 0;
  std::vector<HandleTunnelLoop> handles, tunnels;
};

struct LoopsResult {
  std::vector<ComponentLoops> components;
  int32_t coarse_target = 0;  ///< decimation target used by the coarse route (0 if unused)
  int32_t coarse_rounds = 0;  ///< refinement rounds against coarse self-intersections
  int32_t coarse_samples_added = 0;
  double seconds_prepare = 0, seconds_decimate = 0, seconds_intersections = 0, seconds_tetrahedralize = 0, seconds_persistence = 0,
         seconds_select = 0, seconds_map = 0, seconds_shorten = 0, seconds_verify = 0;
};

/// Shortens a simple closed loop of mesh edges (caller's vertex ids, last joins first) on a closed
/// manifold component without changing its homotopy class (the tightening of step 5; for loops
/// the user edited). Throws std::invalid_argument when the loop is not a simple edge cycle of
/// such a component. params.count_edges picks the metric; the other fields are ignored.
std::vector<int32_t> shorten_loop(const Mesh& mesh, const std::vector<int32_t>& loop, const LoopParams& params = {},
                                  int32_t max_window = 192);

/// Handle and tunnel loops of every component of `mesh`. Throws std::invalid_argument (bad
/// component, TetGen refusal), Cancelled (progress callback said stop), std::logic_error (a
/// self-check failed).
LoopsResult compute_loops(const Mesh& mesh, const LoopParams& params = {});

}  // namespace topstoc
