// Boundary loops and hole filling (thesis 4.2.2; docs/design.md §4.5).
//
// A hole is a boundary loop: a cycle of edges with one triangle each. Filling it adds a patch
// of triangles over the hole's own vertices (hole_triangulation.hpp says how), oriented like the
// surrounding surface, using no edge the surface already has (which would become
// non-manifold). Optionally the patch is refined to the density of the surrounding mesh and
// faired (patch_fairing.hpp). Existing vertices, triangles and their order are kept; patch
// triangles and added vertices are appended.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/edit/edit.hpp"
#include "topstoc/edit/hole_triangulation.hpp"

namespace topstoc {

/// One boundary loop of a mesh.
struct BoundaryLoop {
  /// Vertices in order, starting at the lowest id, oriented with the surface on the left (the
  /// way its triangles run along it; by majority where their orientation disagrees).
  std::vector<int32_t> vertices;
  /// A vertex of the loop where the boundary is not manifold (it lies on another boundary loop,
  /// its triangles form several fans, or an edge at it has more than two triangles), or -1.
  int32_t nonmanifold_vertex = -1;
  /// The loop is the border of a lone triangle (a component of one triangle): its patch would
  /// duplicate that triangle.
  bool lone_triangle = false;
  /// Loops that touch a non-manifold vertex or border a lone triangle cannot be filled.
  bool fillable() const { return nonmanifold_vertex < 0 && !lone_triangle; }
};

/// Every boundary loop, ordered by their first (lowest) vertex. Triangles with a repeated vertex
/// throw std::invalid_argument. O(m * valence), parallel.
std::vector<BoundaryLoop> boundary_loops(const int32_t* triangles, int64_t num_triangles, int32_t num_vertices);

struct FillOptions {
  HoleTriangulationOptions triangulation;
  /// Refine the patch towards the edge length around the hole (Liepa 2003): adds vertices.
  bool refine = false;
  /// Move the added vertices to a smooth (discrete thin-plate) shape; implies refine.
  bool fair = false;
};

/// Fills the given holes, each a boundary cycle of vertex ids (either direction, any start).
/// Throws std::invalid_argument naming the problem: fewer than 3 vertices, a repeated vertex or
/// one shared by two holes, two consecutive vertices not joined by a boundary edge, a hole
/// touching a non-manifold vertex, a hole that is the border of a lone triangle (its patch
/// would duplicate it), a non-finite coordinate on the hole. Holes are filled in parallel; the
/// result does not depend on the thread count.
EditResult fill_loops(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                      const std::vector<std::vector<int32_t>>& holes, const FillOptions& options);

/// fill_loops on the mesh an earlier edit produced, in place: patches are appended to `mesh` and
/// its maps keep leading back to that edit's input. The triangles are not checked again.
void fill_loops_into(EditResult& mesh, const std::vector<std::vector<int32_t>>& holes, const FillOptions& options);

/// Which boundary loops fill_holes fills.
struct HoleSelection {
  std::vector<int32_t> holes;     ///< indices into boundary_loops(); empty: every loop
  int32_t max_edges = 0;          ///< with `holes` empty: only loops with at most this many edges (0: any)
  bool skip_unfillable = false;   ///< leave loops that are not fillable() open instead of raising
  /// A loop that passes twice through the same point (two of its vertices at exactly the same
  /// position, as left by tools that split non-manifold vertices) cannot be filled without
  /// degenerate or overlapping triangles. Weld such vertices and fill each lobe of the loop on
  /// its own: the duplicates are removed (vertex_source says where every vertex came from).
  bool weld_pinches = true;
};

/// Fills the boundary loops chosen by `selection` (see boundary_loops()). FilledHole::hole is the
/// loop index; a loop welded at pinches gives one patch per lobe. Existing vertices keep their
/// order (minus welded duplicates), existing triangles keep order and corners.
EditResult fill_holes(const double* positions, int32_t num_vertices, const int32_t* triangles, int64_t num_triangles,
                      const HoleSelection& selection, const FillOptions& options);

}  // namespace topstoc
