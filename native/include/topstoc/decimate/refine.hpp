// Quadric refinement: a TopStoc result with a few times the wanted vertices, thinned to the
// target by greedy half-edge collapses ordered by quadric error (Garland & Heckbert 1997).
//
// The stochastic pass does the heavy lifting on the full mesh (fast, topology checked); the
// collapses then pick which of its vertices to drop by how far that takes the surface from the
// *input* (each output vertex carries the summed quadric of the input triangles of its cluster).
// A collapse moves vertex u onto its neighbour v, so every output vertex is still an input
// vertex (or its filtered position) and positions never move. A collapse is done only if it
// keeps every guarantee of the decimation: the link condition holds (so the surface stays a
// manifold of the same topology), no triangle flips or loses all area, and a vertex on a
// border curve (boundary, UV seam, material border, flagged edge) moves only along its curve,
// onto the next vertex of the same curve or a corner, so borders keep their course and their
// sides and attributes keep carrying over exactly. Corners never move, closed curves keep three
// vertices. User guidance scales the costs; control points are never removed.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/decimate/decimate.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

struct RefineParams {
  int32_t target_vertices = 0;
  /// u per caller vertex in [-1, 1] (the decimation's guidance), or null. Removing a vertex
  /// costs 16^u times its quadric error (painted detail is dearer to remove, u = -1 cheaper);
  /// u = 1 vertices (control points) are never removed. A flat painted region still thins out
  /// (its error is zero whatever the weight): plain TopStoc follows paint more strictly.
  const double* guidance = nullptr;
};

/// Thins `result` (a finished decimation of `mesh`, in the caller's ids) to
/// params.target_vertices output vertices where collapses allow; updates every field of the
/// result (kept, positions, triangles, sources, labels) and its refine_* figures. The sample
/// list is left as it was: replaying it with the same target reproduces the result.
void refine_by_collapses(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params,
                         DecimateResult& result);

}  // namespace topstoc
