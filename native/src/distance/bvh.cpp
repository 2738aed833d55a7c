#include "topstoc/distance/bvh.hpp"
#include "topstoc/core/parallel.hpp"
#include "distance/radix_sort.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace topstoc {

namespace {

constexpr int32_t kLeafSize = 4;

inline double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline double distance2(const double* a, const double* b) {
  const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return dot(d, d);
}

// Closest point of segment [a, b] to p (a point when a == b).
double closest_point_on_segment(const double* p, const double* a, const double* b, double* out) {
  const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double length2 = dot(ab, ab);
  const double t = length2 > 0.0 ? std::clamp(dot(ap, ab) / length2, 0.0, 1.0) : 0.0;
  for (int k = 0; k < 3; ++k) out[k] = a[k] + t * ab[k];
  return distance2(p, out);
}

// Squared distance from p to an axis-aligned box (0 inside).
inline double box_distance2(const double* p, const double* lo, const double* hi) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double below = lo[k] - p[k], above = p[k] - hi[k];
    const double d = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
    d2 += d * d;
  }
  return d2;
}

// A box whose distance exceeds the best one by less than this relative slack is still opened, so
// that rounding in the box test never hides a triangle at the same distance (exact ties matter
// for the deterministic lower-id tie-break).
constexpr double kPruneSlack = 1.0 + 1e-12;

}  // namespace

// A triangle's place on a Morton curve through its centroid, next to its id: the build sorts
// these, so that each node's triangles are one run of the curve.
struct TriangleBvh::BuildItem {
  uint64_t code;
  int32_t id;
};

namespace {

constexpr int kAxisBits = 14;  // cells per axis of the Morton curve: 2^14

// The kAxisBits bits of x spread to every third bit.
uint64_t spread_bits(uint64_t x) {
  uint64_t out = 0;
  for (int b = 0; b < kAxisBits; ++b) out |= ((x >> b) & 1) << (3 * b);
  return out;
}

}  // namespace

double closest_point_on_triangle(const double* p, const double* a, const double* b, const double* c,
                                 double* closest) {
  // Voronoi regions of the corners, then the edges, then the interior (the region tests of
  // Ericson, Real-Time Collision Detection, 5.1.5), with guarded divisions so that degenerate
  // triangles never produce NaN.
  const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto set = [&](const double* q) {
    for (int k = 0; k < 3; ++k) closest[k] = q[k];
    return distance2(p, closest);
  };
  if (d1 <= 0.0 && d2 <= 0.0) return set(a);
  const double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return set(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) {
    const double v = d1 / (d1 - d3);
    const double q[3] = {a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]};
    return set(q);
  }
  const double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return set(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) {
    const double w = d2 / (d2 - d6);
    const double q[3] = {a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]};
    return set(q);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    const double q[3] = {b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])};
    return set(q);
  }
  const double denominator = va + vb + vc;
  if (denominator > 0.0) {
    const double v = vb / denominator, w = vc / denominator;
    const double q[3] = {a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w};
    return set(q);
  }
  // Degenerate triangle: it is the union of its three sides.
  double best = std::numeric_limits<double>::infinity();
  const double* corners[3] = {a, b, c};
  for (int side = 0; side < 3; ++side) {
    double q[3];
    const double d = closest_point_on_segment(p, corners[side], corners[(side + 1) % 3], q);
    if (d < best) {
      best = d;
      for (int k = 0; k < 3; ++k) closest[k] = q[k];
    }
  }
  return best;
}

TriangleBvh::TriangleBvh(const double* positions, const int32_t* triangles, int64_t num_triangles) {
  // Triangles sorted along a Morton curve through their centroids (Lauterbach et al. 2009,
  // "LBVH"), then split where the curve crosses the highest differing cell boundary: linear
  // time, where median splits took O(m log m) and most of a million-triangle measurement.
  const int32_t m = static_cast<int32_t>(num_triangles);
  auto centroid = [&](int32_t f, int k) {
    const int32_t* t = &triangles[3 * size_t(f)];
    return (positions[3 * size_t(t[0]) + k] + positions[3 * size_t(t[1]) + k] + positions[3 * size_t(t[2]) + k]) / 3.0;
  };
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<double>::infinity(), hi[k] = -lo[k];
  for (int32_t f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) {
      const double x = centroid(f, k);
      lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x);
    }
  std::vector<BuildItem> items(m);
  const double cells = double((1 << kAxisBits) - 1);
  parallel_for(0, m, 100000, [&](int32_t f) {
    uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double unit = hi[k] > lo[k] ? (centroid(f, k) - lo[k]) / (hi[k] - lo[k]) : 0.0;
      code |= spread_bits(uint64_t(std::clamp(unit, 0.0, 1.0) * cells)) << (2 - k);
    }
    items[f] = {code, f};
  });
  radix_sort(items, 3 * kAxisBits);
  // The corners in leaf order, so that a leaf's triangles sit together in memory.
  triangle_ids_.resize(m);
  corners_.resize(9 * size_t(m));
  parallel_for(0, m, 100000, [&](int32_t s) {
    const int32_t f = triangle_ids_[s] = items[s].id;
    for (int c = 0; c < 3; ++c)
      std::copy_n(&positions[3 * size_t(triangles[3 * size_t(f) + c])], 3, &corners_[9 * size_t(s) + 3 * c]);
  });
  nodes_.reserve(2 * size_t(m / kLeafSize + 1));
  build(0, m, items.data());
}

int32_t TriangleBvh::build(int32_t begin, int32_t end, const BuildItem* items) {
  // The split: the first item whose code has the highest bit in which the range's first and last
  // codes differ (the middle when all codes are equal). Boxes come from the children, so each
  // slot's corners are read once.
  const int32_t index = static_cast<int32_t>(nodes_.size());
  nodes_.push_back(Node{});
  Node node{};
  if (end - begin <= kLeafSize) {
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = std::numeric_limits<double>::infinity();
      node.hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (int64_t i = 9 * int64_t(begin); i < 9 * int64_t(end); i += 3)
      for (int k = 0; k < 3; ++k) {
        node.lo[k] = std::min(node.lo[k], corners_[size_t(i) + k]);
        node.hi[k] = std::max(node.hi[k], corners_[size_t(i) + k]);
      }
    node.first = begin;
    node.count = end - begin;
  } else {
    const uint64_t differ = items[begin].code ^ items[end - 1].code;
    int32_t middle = begin + (end - begin) / 2;
    if (differ != 0) {
      uint64_t bit = uint64_t(1) << (3 * kAxisBits - 1);
      while (!(differ & bit)) bit >>= 1;
      middle = int32_t(std::partition_point(items + begin, items + end,
                                            [bit](const BuildItem& x) { return !(x.code & bit); }) - items);
    }
    const int32_t left = build(begin, middle, items);
    const int32_t right = build(middle, end, items);
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = std::min(nodes_[left].lo[k], nodes_[right].lo[k]);
      node.hi[k] = std::max(nodes_[left].hi[k], nodes_[right].hi[k]);
    }
    node.first = right;
    node.count = 0;
  }
  nodes_[index] = node;
  return index;
}

double TriangleBvh::slot_distance2(const double* p, int32_t slot, double* closest) const {
  const double* t = &corners_[9 * size_t(slot)];
  return closest_point_on_triangle(p, t, t + 3, t + 6, closest);
}

ClosestHit TriangleBvh::closest(const double* p, int32_t hint_slot) const {
  ClosestHit hit;
  hit.distance2 = std::numeric_limits<double>::infinity();
  auto consider = [&](int32_t slot) {
    double q[3];
    const double d2 = slot_distance2(p, slot, q);
    if (d2 < hit.distance2 || (d2 == hit.distance2 && triangle_ids_[slot] < hit.triangle)) {
      hit.distance2 = d2;
      hit.triangle = triangle_ids_[slot];
      hit.slot = slot;
      for (int k = 0; k < 3; ++k) hit.point[k] = q[k];
    }
  };
  if (hint_slot >= 0 && hint_slot < int32_t(triangle_ids_.size())) consider(hint_slot);

  struct Entry {
    int32_t node;
    double distance2;
  };
  Entry stack[128];
  int depth = 0;
  stack[depth++] = {0, box_distance2(p, nodes_[0].lo, nodes_[0].hi)};
  while (depth > 0) {
    const Entry entry = stack[--depth];
    if (entry.distance2 > hit.distance2 * kPruneSlack) continue;
    const Node& node = nodes_[entry.node];
    if (node.count > 0) {
      for (int32_t s = node.first; s < node.first + node.count; ++s) consider(s);
      continue;
    }
    const int32_t left = entry.node + 1, right = node.first;
    const double dl = box_distance2(p, nodes_[left].lo, nodes_[left].hi);
    const double dr = box_distance2(p, nodes_[right].lo, nodes_[right].hi);
    // Push the farther child first so that the nearer one is searched first.
    if (dl <= dr) {
      if (dr <= hit.distance2 * kPruneSlack) stack[depth++] = {right, dr};
      if (dl <= hit.distance2 * kPruneSlack) stack[depth++] = {left, dl};
    } else {
      if (dl <= hit.distance2 * kPruneSlack) stack[depth++] = {left, dl};
      if (dr <= hit.distance2 * kPruneSlack) stack[depth++] = {right, dr};
    }
  }
  return hit;
}

}  // namespace topstoc
