// TriangleBvh's slabs (bvh.hpp): where a fan of slivers shares a centre, every sliver's
// axis-aligned box reaches it, the boxes of a whole side of the fan hold a query point near the
// surface and the closest-point walk reads thousands of triangles per query. A slab along the
// node's mean normal is thin across a run of neighbouring slivers and prunes the others; where
// the fan is flat the slab is its plane, and the node's cone from the centre prunes instead. Both
// only prune nodes whose every triangle is farther than the best found, so answers are unchanged.
#include "topstoc/distance/bvh.hpp"
#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace topstoc {

namespace {

// A sliver: its box's squared diagonal exceeds kSliver times twice its area (about an aspect
// ratio of kSliver / 2; an equilateral triangle gives 2). Slabs are built when at least
// 1 / kSliverShare of the triangles are slivers: elsewhere the boxes prune well and the slabs
// would cost memory (5 doubles per node) and a test per opened node for nothing.
constexpr double kSliver = 64.0;
constexpr int64_t kSliverShare = 8;

void cross(const double* t, double n[3]) {
  const double a[3] = {t[3] - t[0], t[4] - t[1], t[5] - t[2]};
  const double b[3] = {t[6] - t[0], t[7] - t[1], t[8] - t[2]};
  n[0] = a[1] * b[2] - a[2] * b[1], n[1] = a[2] * b[0] - a[0] * b[2], n[2] = a[0] * b[1] - a[1] * b[0];
}

bool same(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

// A corner of slot `first` that every slot in [first, end) has (its offset in corners), or -1.
int64_t shared_corner(const std::vector<double>& corners, int32_t first, int32_t end) {
  for (int c = 0; c < 3; ++c) {
    const double* x = &corners[9 * size_t(first) + 3 * size_t(c)];
    bool all = true;
    for (int32_t s = first + 1; s < end && all; ++s)
      all = same(x, &corners[9 * size_t(s)]) || same(x, &corners[9 * size_t(s) + 3]) || same(x, &corners[9 * size_t(s) + 6]);
    if (all) return 9 * int64_t(first) + 3 * c;
  }
  return -1;
}

// Below this cosine of a cone's half-angle (about 84 degrees) the cone bounds too little to keep.
constexpr double kWidestCone = 0.1;

bool sliver(const double* t) {
  double n[3], diagonal2 = 0.0;
  cross(t, n);
  for (int k = 0; k < 3; ++k) {
    const double extent = std::max({t[k], t[k + 3], t[k + 6]}) - std::min({t[k], t[k + 3], t[k + 6]});
    diagonal2 += extent * extent;
  }
  return diagonal2 > kSliver * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

}  // namespace

void TriangleBvh::build_slabs() {
  const int32_t m = static_cast<int32_t>(num_triangles());
  int64_t slivers = 0;
  for (int32_t s = 0; s < m; ++s) slivers += sliver(&corners_[9 * size_t(s)]);
  if (slivers * kSliverShare < m) return;
  // Each node's slots and summed area normal; children have higher indices than their parent,
  // so a pass from the last node back sees them first.
  const int32_t count = static_cast<int32_t>(num_nodes());
  std::vector<int32_t> begin(count), end(count);
  std::vector<double> sum(3 * size_t(count), 0.0);
  for (int32_t i = count - 1; i >= 0; --i) {
    const Node& node = nodes_[i];
    double* total = &sum[3 * size_t(i)];
    if (node.count > 0) {
      begin[i] = node.first, end[i] = node.first + node.count;
      for (int32_t s = begin[i]; s < end[i]; ++s) {
        double n[3];
        cross(&corners_[9 * size_t(s)], n);
        for (int k = 0; k < 3; ++k) total[k] += n[k];
      }
    } else {
      begin[i] = begin[i + 1], end[i] = end[node.first];
      for (int k = 0; k < 3; ++k) total[k] = sum[3 * size_t(i + 1) + k] + sum[3 * size_t(node.first) + k];
    }
  }
  // Each node's shared corner (the apex of a fan sector): a leaf's, or its children's when equal.
  std::vector<int64_t> apex(count, -1);
  for (int32_t i = count - 1; i >= 0; --i) {
    const Node& node = nodes_[i];
    if (node.count > 0) {
      apex[i] = shared_corner(corners_, begin[i], end[i]);
    } else if (apex[i + 1] >= 0 && apex[node.first] >= 0 && same(&corners_[apex[i + 1]], &corners_[apex[node.first]])) {
      apex[i] = apex[i + 1];
    }
  }
  slabs_.resize(count);
  parallel_for(0, count, 256, [&](int32_t i) {
    Slab& slab = slabs_[i];
    if (apex[i] >= 0) build_cone(slab, &corners_[apex[i]], begin[i], end[i]);
    const double* total = &sum[3 * size_t(i)];
    const double length = std::sqrt(total[0] * total[0] + total[1] * total[1] + total[2] * total[2]);
    slab.lo = -std::numeric_limits<double>::infinity(), slab.hi = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) slab.normal[k] = 0.0;
    if (!(length > 0.0) || !std::isfinite(length)) return;  // normals that cancel: no slab
    for (int k = 0; k < 3; ++k) slab.normal[k] = total[k] / length;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int32_t s = begin[i]; s < end[i]; ++s)
      for (int c = 0; c < 3; ++c) {
        const double* x = &corners_[9 * size_t(s) + 3 * size_t(c)];
        const double d = slab.normal[0] * x[0] + slab.normal[1] * x[1] + slab.normal[2] * x[2];
        lo = std::min(lo, d), hi = std::max(hi, d);
      }
    slab.lo = lo, slab.hi = hi;
  });
}

// The cone from `apex` holding the corners of slots [first, end): around their mean direction,
// as wide as the widest of them (a little wider, for rounding); none when wider than kWidestCone.
void TriangleBvh::build_cone(Slab& slab, const double* apex, int32_t first, int32_t end) const {
  double axis[3] = {0, 0, 0};
  auto direction = [&](const double* x, double u[3]) {
    const double d[3] = {x[0] - apex[0], x[1] - apex[1], x[2] - apex[2]};
    const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(length > 0.0) || !std::isfinite(length)) return false;
    for (int k = 0; k < 3; ++k) u[k] = d[k] / length;
    return true;
  };
  for (int32_t s = first; s < end; ++s)
    for (int c = 0; c < 3; ++c)
      if (double u[3]; direction(&corners_[9 * size_t(s) + 3 * size_t(c)], u))
        for (int k = 0; k < 3; ++k) axis[k] += u[k];
  const double length = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  if (!(length > 0.0) || !std::isfinite(length)) return;
  for (int k = 0; k < 3; ++k) axis[k] /= length;
  double lowest = 1.0;
  for (int32_t s = first; s < end; ++s)
    for (int c = 0; c < 3; ++c)
      if (double u[3]; direction(&corners_[9 * size_t(s) + 3 * size_t(c)], u))
        lowest = std::min(lowest, axis[0] * u[0] + axis[1] * u[1] + axis[2] * u[2]);
  lowest -= 1e-9;
  if (!(lowest >= kWidestCone)) return;
  for (int k = 0; k < 3; ++k) slab.apex[k] = apex[k], slab.axis[k] = axis[k];
  slab.cos_half = lowest;
  slab.sin_half = std::sqrt(std::max(0.0, 1.0 - lowest * lowest));
}

}  // namespace topstoc
