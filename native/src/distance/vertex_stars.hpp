// Distances from points to a big surface A through the triangles around its vertices (their
// stars), for the quick Hausdorff bound (quick_hausdorff_bound), which builds no search tree over
// A's triangles: any triangle of A bounds a point's distance to A from above, and the nearest
// point lies in a triangle with a corner within that bound plus A's reach of the point.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "distance/vertex_grid.hpp"
#include "topstoc/distance/bvh.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

/// The distance from x to triangle f of s.
double distance_to_triangle(const double* x, const Surface& s, int32_t f);

/// The triangles around each vertex of A. A vertex with more than kWideStar of them (a fan's
/// centre, a cone's apex) keeps a search tree over them: a pass over its thousands of triangles
/// for every point near it made a fanned cap's bound take minutes.
class Stars {
 public:
  static constexpr int64_t kWideStar = 64;
  explicit Stars(const Surface& a);
  int64_t begin(int32_t v) const { return offset_[size_t(v)]; }
  int64_t end(int32_t v) const { return offset_[size_t(v) + 1]; }
  int32_t triangle(int64_t i) const { return triangle_[size_t(i)]; }
  bool wide(int32_t v) const { return end(v) - begin(v) > kWideStar; }
  struct Nearest {
    double distance;
    int32_t triangle;  // -1 for a vertex of no triangle
  };
  /// The triangle around v nearest to y (the first in star order among equals).
  Nearest nearest(const double* y, int32_t v) const;

 private:
  const Surface& a_;
  std::vector<int64_t> offset_;
  std::vector<int32_t> triangle_;
  std::vector<int32_t> wide_;  // the wide vertices, in increasing order; trees_[i] is wide_[i]'s
  std::vector<std::unique_ptr<TriangleBvh>> trees_;
};

/// An upper bound of a point's distance to A, attained by one triangle of A.
struct StarBound {
  double distance;
  int32_t vertex;    // the vertex of A it was found around: where a nearby point's walk starts
  int32_t triangle;  // the triangle of A at that distance
};

/// From `start`, steps to the nearest corner of the current vertex's triangles while that is
/// nearer to y (of its nearest triangle, around a wide vertex), then bounds y's distance to A by
/// the triangles around the vertex reached.
StarBound star_distance_bound(const double* y, int32_t start, const Surface& a, const Stars& stars);

/// The distance from y to A, given a bound of it: the nearest point lies in a triangle with a
/// corner within bound + reach of y (reach: no point of a triangle of A is farther from its corners).
StarBound star_exact_distance(const double* y, StarBound bound, double reach, const Surface& a,
                              const VertexGrid& grid, const Stars& stars);

}  // namespace topstoc
