// A guaranteed bracket on the one-sided Hausdorff maximum (the sampled max is only a lower bound).
//
// The distance to a surface, d(x) = min over y in B of |x - y|, is 1-Lipschitz. On a triangle T of
// A with corner distances d0, d1, d2 every point x lies within r(T) of some corner, so
//   max over T of d <= max(d0, d1, d2) + r(T),
// where r(T) is the largest distance from a point of T to its nearest corner: the circumradius
// for a triangle without an obtuse angle, half the longest side otherwise (the nearest-corner
// distance peaks at the circumcentre when it lies in T, on the boundary when not). A second
// bound: d(x) <= dist(x, B_j) for any triangle B_j of B, a convex function of x, so over T it
// peaks at a corner; B_j is taken among the triangles nearest to T's corners and centroid (this
// one makes nearly coincident surfaces cheap, where the first bound never gets small). The search
// keeps every triangle whose bound exceeds the best distance found so far by more than the
// tolerance, splits the one with the highest bound into four at its edge midpoints, measures the
// three new corners, and stops when no triangle can hide a larger distance. This is the scheme of
// CGAL's bounded_error_Hausdorff_distance (Krivograd, Trlep and Zalik 2008; Tang et al. 2009),
// with simple per-triangle bounds.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

class Stars;  // distance/vertex_stars.hpp

// Triangles a lookup measures on average, as a query budget counts them (11-13 on fandisk and
// the Chinese dragon; 334 on a flat fan of 1,500 slivers).
constexpr int64_t kTestedPerQuery = 16;

struct MaxBracket {
  double lower = 0.0;          ///< a distance attained at a point of A: the true max is at least this
  double upper = 0.0;          ///< no point of A is farther than this from B
  double lower_point[3] = {0, 0, 0};
  int32_t lower_triangle = -1; ///< triangle of A holding lower_point when the refinement found it (else -1)
  int64_t queries = 0;         ///< closest-point queries made by the refinement
  int64_t tested = 0;          ///< triangles of the other surface those queries measured or the bounds beneath looked at
  bool converged = true;       ///< upper <= lower * (1 + tolerance) (false when the query budget ran out)
};

/// Brackets max over A of dist(x, B). start: the distance and point already known (e.g. the
/// sampled max); vertex_distance: the distance of every vertex of A used by a triangle (empty:
/// taken from the queries that find each vertex's nearest triangle).
/// relative_tolerance > 0; max_queries bounds the work (the bracket stays valid when it is hit).
MaxBracket bound_max_distance(const Surface& from, const std::vector<double>& vertex_distance, const Surface& to,
                              double start, const double* start_point, double relative_tolerance,
                              int64_t max_queries = 4000000);

/// The same bracket with every used vertex of A measured first: cheaper than the walk down A's
/// tree (below) unless A is far finer than the distances, the usual case of a decimation and its
/// original. Each vertex is bounded by its distance to the triangle of B that a walk from a
/// neighbour's reaches (triangle_walk.hpp), and looked up in B's tree only for the first vertex of
/// each part of A, where a walk runs long, and where its bound exceeds the largest distance looked
/// up (the highest first): the lower bound is A's vertices' largest distance. A piece its corner
/// bounds leave open is cut along an edge or around a vertex of B (fan_cut.hpp) that its corners'
/// triangles share, then bounded by the triangles beneath it, then on its quarters, each by the
/// best of the triangles at its corners (this search only: the others keep the brackets the
/// decimation's fits read). resolution: bounds under resolution x the larger diagonal count as
/// settled (the search's floor; 1e-13 elsewhere), so that a result lying on its original up to
/// rounding is not split down to that rounding (nor its vertices under that floor looked up).
/// from_stars, to_stars: A's and B's triangles around each vertex.
MaxBracket bound_max_from_vertices(const Surface& from, const Surface& to, double relative_tolerance,
                                   double resolution, int64_t max_queries, const Stars& from_stars,
                                   const Stars& to_stars);

/// The same bracket over the listed triangles of A only (start: a distance attained elsewhere).
/// Bounds under resolution x the larger diagonal count as settled (1e-13 by default, as in
/// bound_max_distance). to_stars (to's triangles around each vertex), when
/// given: a piece its corners leave open tries the edge cut, the fan cut (fan_cut.hpp) and its
/// quarters before it is split (the quick bound's; the decimation's fits pass none).
MaxBracket bound_max_over_triangles(const Surface& from, const std::vector<int32_t>& triangles, const Surface& to,
                                    double start, double relative_tolerance, int64_t max_queries,
                                    double resolution = 1e-13, const Stars* to_stars = nullptr);

/// The largest distance from a point of the triangle p to its nearest corner (r(T) above).
double nearest_corner_reach(const double p[3][3]);

/// The same bracket without any distance known beforehand: the search starts from the root of A's
/// own BVH (a node's box bounds its triangles) and opens only the nodes that may hide a larger
/// distance, so a large A close to B costs far fewer queries than measuring all its vertices.
/// threshold (>= 0 to use it): bounds at or below it need no refinement and a distance above it
/// ends the search, so only whether the max exceeds it is decided (cheaper near neither).
/// lean (with a threshold): nodes their bound settles are not sampled for the lower bound, so
/// `lower` is the largest distance met on the way, not the best the walk could report (the
/// verdict holds; the fit, which reads lower, keeps the full walk).
MaxBracket bound_max_distance_by_tree(const Surface& from, const Surface& to, double relative_tolerance,
                                      int64_t max_queries = 4000000, double threshold = -1.0, bool lean = false);

}  // namespace topstoc
