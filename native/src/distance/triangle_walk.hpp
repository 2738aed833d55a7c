// A walk over a surface's triangles toward a point: from a triangle near it (a neighbour's, as a
// mesh's vertices are measured one after another), step across the side of the current triangle
// that the point lies farthest beyond, seen along the triangle's normal, until it lies over the
// triangle (or beyond a border only, or the step would go back); then, unless that triangle is
// close enough, on to a nearer edge neighbour while there is one (next to a crease the triangle
// under the point is not the nearest). The distance to the triangle it ends on bounds the point's
// distance to the surface from above, and is that distance where the surface near the point is a
// single sheet; a step costs a few products, a tree lookup several triangle tests and twenty box
// tests.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

class Stars;  // distance/vertex_stars.hpp

class TriangleWalk {
 public:
  /// Over s, whose triangles around each vertex are `stars`.
  TriangleWalk(const Surface& s, const Stars& stars);

  struct End {
    double distance2;  ///< squared distance from the point to `triangle`
    int32_t triangle;  ///< where the walk ended
    bool settled;      ///< false when it would still step after max_steps steps
  };
  /// From triangle `start`, at most max_steps steps toward x; the last steps, to nearer edge
  /// neighbours, are not looked for once the triangle reached lies within `close` of x.
  End walk(const double* x, int32_t start, int max_steps, double close) const;

  /// The triangle across side j (corners j, j + 1) of triangle f, -1 on a border (one of them
  /// where the side is non-manifold).
  int32_t neighbour(int32_t f, int j) const {
    const int32_t known = across_[3 * size_t(f) + size_t(j)];
    return known != kUnknown ? known : across(f, j);
  }

 private:
  static constexpr int32_t kUnknown = -2;
  const Surface& s_;
  const Stars& stars_;
  // 3 per triangle: the triangle across side j (corners j, j + 1), -1 on a border, found when
  // first stepped over (a walk reaches a small part of a big surface); so one walk object is
  // used by one thread at a time
  mutable std::vector<int32_t> across_;
  int32_t across(int32_t f, int j) const;
  double distance2(const double* x, int32_t triangle) const;
  int beyond(const double* x, int32_t triangle) const;
};

/// The triangles of s breadth first (across shared corners) from each one not yet reached, in
/// order: every triangle but the first of a connected part shares a corner with one before it, so
/// that a walk for each of its corners can start from a neighbour's triangle.
std::vector<int32_t> walk_order(const Surface& s, const Stars& stars);

}  // namespace topstoc
