// Hausdorff distance between two triangle meshes (docs/design.md §3; thesis 4.7.1, A.5).
//
// One-sided distance from surface A to surface B: A is sampled, and every sample's nearest
// point on B is found through B's bounding volume hierarchy (bvh.hpp). The sampling follows
// Aspert et al. 2002 ("MESH") and Cignoni et al. 1998 ("Metro"): one length `step` for the
// whole surface; every vertex is a sample, every edge gets points no more than `step` apart,
// and every triangle is cut into n x n similar sub-triangles, n = ceil(longest edge / step),
// whose centroids are its area samples (each stands for area / n^2 of the surface).
//   - max and the per-element errors use every sample (vertices, edges, faces);
//   - mean, RMS and the percentile are area-weighted over the face samples (a centroid-rule
//     integral of the distance over the surface).
// Symmetric figures follow MESH: the larger of the two one-sided values.
//
// Everything here works on the caller's arrays as given (no vertex is renumbered, nothing is
// dropped: a degenerate triangle is measured as the segment or point it is). Results are the
// same with any number of threads.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "topstoc/distance/bvh.hpp"

namespace topstoc {

/// A triangle mesh validated for measurement, with its edges and its BVH (both built on first use).
class Surface {
 public:
  /// positions: 3 per vertex; triangles: 3 vertex ids per triangle. Throws std::invalid_argument
  /// naming the offending element for empty input, non-finite coordinates and indices out of range.
  Surface(std::vector<double> positions, std::vector<int32_t> triangles);

  int32_t num_vertices() const { return int32_t(positions_.size() / 3); }
  int32_t num_triangles() const { return int32_t(triangles_.size() / 3); }
  const std::vector<double>& positions() const { return positions_; }
  const std::vector<int32_t>& triangles() const { return triangles_; }
  /// Distinct undirected edges (2 vertex ids per edge, lower first) and, per triangle side c
  /// (corner c to c+1), its edge id; -1 where the side repeats a vertex.
  const std::vector<int32_t>& edges() const;
  const std::vector<int32_t>& face_edges() const;
  /// 1 for vertices used by a triangle.
  const std::vector<uint8_t>& used() const { return used_; }
  /// Bounding-box diagonal of the vertices used by triangles.
  double diagonal() const { return diagonal_; }
  double area() const { return area_; }
  /// The closest-point index (built once, thread-safe).
  const TriangleBvh& bvh() const;

 private:
  void build_edges() const;

  std::vector<double> positions_;
  std::vector<int32_t> triangles_;
  mutable std::vector<int32_t> edges_, face_edges_;
  mutable std::once_flag edges_once_;
  std::vector<uint8_t> used_;
  double diagonal_ = 0.0, area_ = 0.0;
  mutable std::once_flag bvh_once_;
  mutable std::unique_ptr<TriangleBvh> bvh_;
};

/// Sample points of a surface for a given step (see the file comment).
struct SurfaceSamples {
  double step = 0.0;
  std::vector<double> points;         ///< 3 per sample: vertex samples, then edge samples, then face samples
  std::vector<int32_t> element;       ///< vertex id, edge id or triangle id of each sample
  int64_t num_vertex_samples = 0;
  int64_t num_edge_samples = 0;
  int64_t num_face_samples = 0;
  std::vector<int64_t> face_offsets;  ///< face samples of triangle f: [face_offsets[f], face_offsets[f+1]) (absolute)
  std::vector<double> face_weight;    ///< area each sample of triangle f stands for (area / n^2)
  int64_t size() const { return int64_t(element.size()); }
};

/// Samples `surface` with spacing `step` (> 0). Throws std::invalid_argument when the step is not
/// positive or would need more than 100 million samples.
SurfaceSamples sample_surface(const Surface& surface, double step);

/// The step for which sample_surface gives about `samples` samples (never more than that, unless
/// even the coarsest sampling, every vertex plus one sample per triangle, exceeds it).
double step_for_sample_count(const Surface& surface, int64_t samples);

/// Nearest points on `surface` of `count` points (3 coordinates each), in parallel. `within` >= 0:
/// a point within that distance of the surface may get any triangle within it (TriangleBvh::closest).
std::vector<ClosestHit> closest_points(const Surface& surface, const double* points, int64_t count,
                                       double within = -1.0);

/// Distances from one surface's samples to another surface.
struct OneSidedDistance {
  double max = 0.0;
  double mean = 0.0;          ///< area-weighted
  double rms = 0.0;           ///< area-weighted
  double percentile = 0.0;    ///< distance below which the asked fraction of the area lies (NaN if not asked)
  double max_point[3] = {0, 0, 0};  ///< the point where the maximum was found
  /// No point of the sampled surface is farther than this: with bounded-error refinement
  /// (bounded_max.hpp) max <= true maximum <= max_upper <= max * (1 + tolerance); without it, +inf.
  double max_upper = std::numeric_limits<double>::infinity();
  int64_t refine_queries = 0;       ///< closest-point queries the refinement made
  int64_t samples = 0;
  std::vector<double> vertex_distance;  ///< per vertex of the sampled surface; NaN for vertices in no triangle
  std::vector<double> face_max;         ///< per triangle: max over its face, edge and corner samples
};

/// Distances from `samples` (taken on `from`) to `to`. percentile_fraction in (0, 1], or <= 0 to
/// skip the percentile.
OneSidedDistance one_sided_distance(const Surface& from, const SurfaceSamples& samples, const Surface& to,
                                    double percentile_fraction);

/// A guaranteed bracket of the one-sided maximum: lower <= max over `from` of dist(x, to) <= upper.
struct OneSidedBracket {
  double lower = 0.0, upper = 0.0;
  double lower_point[3] = {0, 0, 0};  ///< a point of `from` at distance `lower`
  int64_t queries = 0;     ///< closest-point queries made (vertices included)
  bool converged = true;   ///< upper <= lower * (1 + tolerance); false when max_queries ran out
};

/// Brackets the one-sided maximum from `from` to `to` without sampling `from`: a walk down `from`'s
/// BVH opening only the boxes that may hide a larger distance, then the bounded refinement of
/// their triangles (bounded_max.hpp), until the relative gap is within `tolerance` (> 0) or
/// `max_queries` queries were made (the bracket holds either way). threshold >= 0: stop as soon as
/// the max is known to lie above it or at most at it (the bracket is then only as tight as that needs;
/// `lower` is then only the largest distance the walk met, bounded_max.hpp's lean walk).
OneSidedBracket bracket_one_sided_max(const Surface& from, const Surface& to, double tolerance, int64_t max_queries,
                                      double threshold = -1.0);

/// The symmetric maximum between A and B bracketed within `tolerance` (> 0), or under
/// `resolution` x the larger diagonal, or less tightly once `max_queries` queries a side were
/// made: each side starts from every vertex of its surface measured, most by a walk over the other
/// surface from a neighbour's triangle (bounded_max.hpp, bound_max_from_vertices); the two sides
/// run at once on two threads. (Settling the second side
/// against the first one's distance was tried: a higher threshold makes the bound beneath a piece
/// fail more often, and it cost more queries on the horse and armadillo.)
struct SymmetricBracket {
  OneSidedBracket forward, backward;
};
SymmetricBracket bracket_symmetric_max(const Surface& a, const Surface& b, double tolerance, double resolution,
                                       int64_t max_queries);

/// A guaranteed upper bound of the symmetric max between a big surface A and a small one B (a
/// decimation of A) that builds no search structure over A's triangles (quick_bound.cpp).
struct QuickBound {
  double forward_lower = 0.0;   ///< attained: a point of A this far from B
  double forward_upper = 0.0;   ///< no point of A is farther from B
  double backward_lower = 0.0;  ///< attained: a point of B this far from A
  double backward_upper = 0.0;  ///< no point of B is farther from A
  double forward_mean = 0.0;    ///< mean distance from A to B of one vertex per grid cell (an estimate)
  int64_t queries = 0;          ///< closest-point queries on B's BVH
  int64_t grid_queries = 0;     ///< nearest-vertex queries on A's grid
  int64_t refined = 0;          ///< triangles of A bracketed exactly
};

/// The bound for a (big) and b (small); bounds are split until within (1 + tolerance) of a distance found,
/// or until under resolution x the larger diagonal (a result lying on its original is not split down
/// to the coordinates' rounding; at least 1e-12).
QuickBound quick_hausdorff_bound(const Surface& a, const Surface& b, double tolerance, double resolution = 1e-12);

struct HausdorffParams {
  int64_t samples = 1000000;   ///< wanted samples on the first surface (ignored when step > 0)
  double step = 0.0;           ///< sample spacing; 0 = derive from `samples`
  double percentile = 0.95;    ///< fraction for the k-th ranked distance; <= 0 skips it
  double max_tolerance = 1e-3; ///< relative gap allowed between max and max_upper; <= 0: sampled max only
};

struct HausdorffResult {
  OneSidedDistance forward;    ///< from A to B: samples on A (per-vertex errors of A)
  OneSidedDistance backward;   ///< from B to A: samples on B (per-face errors of B)
  double symmetric_max = 0.0, symmetric_mean = 0.0, symmetric_rms = 0.0, symmetric_percentile = 0.0;
  double symmetric_max_upper = std::numeric_limits<double>::infinity();  ///< guaranteed bound (see max_upper)
  double diagonal = 0.0;       ///< bounding-box diagonal of A
  double step = 0.0;           ///< sample spacing used on both surfaces
};

/// Forward, backward and symmetric Hausdorff distance between A (the original) and B (its
/// approximation), both sampled with the same step. Throws std::invalid_argument on bad params.
HausdorffResult hausdorff(const Surface& a, const Surface& b, const HausdorffParams& params);

/// The same, reusing samples of A taken earlier (their step is used for B too).
HausdorffResult hausdorff(const Surface& a, const SurfaceSamples& a_samples, const Surface& b, double percentile,
                          double max_tolerance = 1e-3);

}  // namespace topstoc
