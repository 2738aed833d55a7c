// Triangulating one hole in space, given its boundary polygon. In order of preference:
//  1. Planar (thesis 4.2.2): project the polygon on a best-fit plane (the Newell plane, whose
//     normal is the polygon's area vector; then the least-squares plane; then the plane facing
//     the surrounding triangles) and, if the projection is a simple polygon, triangulate it in
//     2D (constrained Delaunay). The patch is then a height field over that plane: it cannot
//     overlap itself, and every triangle faces the way the boundary turns.
//  2. Minimum weight (Liepa 2003, after Barequet & Sharir 1995): for holes up to a size limit,
//     dynamic programming over all triangulations, minimising first the largest dihedral angle
//     (between neighbouring patch triangles and against the surface around the hole) and then
//     the area. Handles non-planar and self-overlapping projections; O(k^3).
//  3. Split: a long non-planar hole is cut along its narrowest chord into two smaller holes,
//     each filled by the same rules.
//  4. Fan around an added centre vertex, when every triangulation on the boundary's corners
//     would reuse an edge the surface already has.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "topstoc/edit/polygon_triangulation.hpp"

namespace topstoc {

enum class FillMethod : int32_t { Planar = 0, MinimumWeight = 1, Split = 2, Fan = 3 };

/// "planar", "minimum_weight", "split" or "fan".
const char* fill_method_name(FillMethod method);

struct HoleTriangulationOptions {
  bool planar = true;             ///< try the planar projection first (false: go straight to 3D)
  int32_t max_dp_corners = 300;   ///< minimum-weight triangulation up to this many corners (O(k^3): ~0.1 s at 300)
};

/// One hole: corners in patch order (the patch's triangles turn the same way), and for each
/// side i (corner i to corner i + 1) the unit normal of the surface triangle beyond it, or zeros.
struct Hole {
  std::vector<double> points;        ///< 3 per corner
  std::vector<double> side_normals;  ///< 3 per side
  ForbiddenDiagonal forbidden;       ///< diagonals that must not be used (existing edges)
};

struct HoleTriangulation {
  /// Corner-index triples; an index k + j refers to added_points' j-th point.
  std::vector<std::array<int32_t, 3>> triangles;
  std::vector<double> added_points;  ///< 3 per added vertex (only the fan adds any)
  FillMethod method = FillMethod::Planar;  ///< the last resort any part needed
  double normal[3] = {0, 0, 0};           ///< unit normal of the plane used, or the Newell normal
};

/// Triangulates a hole of at least 3 corners. Never fails: the fan is the last resort.
HoleTriangulation triangulate_hole(const Hole& hole, const HoleTriangulationOptions& options);

}  // namespace topstoc
