#include "topstoc/distance/bvh.hpp"
#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>
#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#endif

namespace topstoc {

namespace {

constexpr int32_t kLeafSize = 4;
// Trees over at least this many triangles build the root's two halves side by side.
constexpr int32_t kParallelBuild = 4096;

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

// The gap between p and a box along one axis: below = lo - p, above = p - hi. The same value as
// `below > 0 ? below : (above > 0 ? above : 0)` (NaN included) since lo <= hi, so both are never
// positive; written as two maxima (MAXPD's operand order: the second when unordered) so that the
// x and y axes can share one SSE2 instruction.
inline double axis_gap(double below, double above) {
  const double outside = above > 0.0 ? above : 0.0;
  return below > outside ? below : outside;
}

// Squared distance from p to an axis-aligned box (0 inside), summed as (x^2 + y^2) + z^2 on
// every path, so the SSE2 and the scalar paths give the same bits as the scalar loop it replaced.
inline double box_distance2(const double* p, const double* lo, const double* hi) {
#if defined(__SSE2__) || defined(_M_X64)
  const __m128d pxy = _mm_loadu_pd(p);  // x and y in the two lanes of one register
  const __m128d outside = _mm_max_pd(_mm_sub_pd(pxy, _mm_loadu_pd(hi)), _mm_setzero_pd());
  const __m128d gap = _mm_max_pd(_mm_sub_pd(_mm_loadu_pd(lo), pxy), outside);
  const __m128d square = _mm_mul_pd(gap, gap);
  const double dz = axis_gap(lo[2] - p[2], p[2] - hi[2]);
  return (_mm_cvtsd_f64(square) + _mm_cvtsd_f64(_mm_unpackhi_pd(square, square))) + dz * dz;
#else
  double d[3];
  for (int k = 0; k < 3; ++k) d[k] = axis_gap(lo[k] - p[k], p[k] - hi[k]);
  return (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2];
#endif
}

// Squared distance from p to the box of a triangle's three corners (9 coordinates): the
// triangle is no nearer, so a leaf skips the triangle test where this exceeds the best hit. The
// corners' x and y are compared in registers (a box stored to memory and loaded back as one
// register stalls the load).
inline double corner_box_distance2(const double* p, const double* t) {
#if defined(__SSE2__) || defined(_M_X64)
  const __m128d a = _mm_loadu_pd(t), b = _mm_loadu_pd(t + 3), c = _mm_loadu_pd(t + 6);
  const __m128d lo = _mm_min_pd(_mm_min_pd(a, b), c), hi = _mm_max_pd(_mm_max_pd(a, b), c);
  const __m128d pxy = _mm_loadu_pd(p);
  const __m128d outside = _mm_max_pd(_mm_sub_pd(pxy, hi), _mm_setzero_pd());
  const __m128d gap = _mm_max_pd(_mm_sub_pd(lo, pxy), outside);
  const __m128d square = _mm_mul_pd(gap, gap);
  const double z_lo = std::min(std::min(t[2], t[5]), t[8]), z_hi = std::max(std::max(t[2], t[5]), t[8]);
  const double dz = axis_gap(z_lo - p[2], p[2] - z_hi);
  return (_mm_cvtsd_f64(square) + _mm_cvtsd_f64(_mm_unpackhi_pd(square, square))) + dz * dz;
#else
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min(std::min(t[k], t[3 + k]), t[6 + k]);
    hi[k] = std::max(std::max(t[k], t[3 + k]), t[6 + k]);
  }
  return box_distance2(p, lo, hi);
#endif
}

// A box whose distance exceeds the best one by less than this relative slack is still opened, so
// that rounding in the box test never hides a triangle at the same distance (exact ties matter
// for the deterministic lower-id tie-break).
constexpr double kPruneSlack = 1.0 + 1e-12;
// The margin of a leaf's triangle skip (search), relative to the coordinates' magnitude: a
// closest point's rounding is under 1e-15 of it.
constexpr double kSkipMargin = 1e-14;

inline double triangle_distance2(const double* p, const double* a, const double* b, const double* c,
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

// The nodes of a subtree over n triangles: median splits down to leaves of at most kLeafSize.
// (Its halves' sizes differ by one at most, so a level holds two sizes at most: memo.)
int32_t subtree_nodes(int32_t n, std::vector<std::pair<int32_t, int32_t>>& memo) {
  if (n <= kLeafSize) return 1;
  for (const auto& [size, nodes] : memo)
    if (size == n) return nodes;
  const int32_t nodes = 1 + subtree_nodes(n / 2, memo) + subtree_nodes(n - n / 2, memo);
  memo.emplace_back(n, nodes);
  return nodes;
}

int32_t subtree_nodes(int32_t n) {
  std::vector<std::pair<int32_t, int32_t>> memo;
  return subtree_nodes(n, memo);
}

}  // namespace

// A triangle's centroid next to its id: the build partitions these in place, so its scans are
// sequential instead of gathering through an index.
struct TriangleBvh::BuildItem {
  double centroid[3];
  int32_t id;
};

double closest_point_on_triangle(const double* p, const double* a, const double* b, const double* c,
                                 double* closest) {
  return triangle_distance2(p, a, b, c, closest);
}

TriangleBvh::TriangleBvh(const double* positions, const int32_t* triangles, int64_t num_triangles) {
  const int32_t m = static_cast<int32_t>(num_triangles);
  corners_.resize(9 * size_t(m));
  std::vector<double> centroids(3 * size_t(m));
  std::vector<double> unordered(9 * size_t(m));
  parallel_for(0, m, 100000, [&](int32_t f) {
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) {
        const double x = positions[3 * size_t(triangles[3 * size_t(f) + c]) + k];
        unordered[9 * size_t(f) + 3 * c + k] = x;
        centroids[3 * size_t(f) + k] += x / 3.0;
      }
  });
  std::vector<BuildItem> items(m);
  for (int32_t f = 0; f < m; ++f) items[f] = {{centroids[3 * size_t(f)], centroids[3 * size_t(f) + 1],
                                                centroids[3 * size_t(f) + 2]}, f};
  nodes_.resize(size_t(subtree_nodes(m)));
  build(0, m, 0, unordered, items.data());
  std::vector<int32_t> order(m);
  for (int32_t s = 0; s < m; ++s) order[s] = items[s].id;
  // Store the corners in leaf order so that a leaf's triangles sit together in memory.
  triangle_ids_ = order;
  parallel_for(0, m, 100000, [&](int32_t s) {
    std::copy_n(&unordered[9 * size_t(order[s])], 9, &corners_[9 * size_t(s)]);
  });
  build_slabs();
  for (int k = 0; k < 3; ++k)
    coordinate_scale_ = std::max({coordinate_scale_, std::abs(nodes_[0].lo[k]), std::abs(nodes_[0].hi[k])});
}

// The distance from p to the slab's cone (apex, axis, half-angle a < 90 degrees), 0 or less
// inside: with v = p - apex at angle f to the axis, |v| sin(f - a), or |v| where f - a passes 90
// degrees (the apex is then the nearest point), less a margin for rounding.
inline double TriangleBvh::cone_gap(const double* p, const Slab& slab) {
  const double v[3] = {p[0] - slab.apex[0], p[1] - slab.apex[1], p[2] - slab.apex[2]};
  const double* a = slab.axis;
  const double along = a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
  const double cross[3] = {a[1] * v[2] - a[2] * v[1], a[2] * v[0] - a[0] * v[2], a[0] * v[1] - a[1] * v[0]};
  const double across = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
  const double sine = across * slab.cos_half - along * slab.sin_half;  // |v| sin(f - a)
  if (!(sine > 0.0)) return 0.0;  // inside the cone: no length needed (most opened nodes)
  const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const double cosine = along * slab.cos_half + across * slab.sin_half;  // |v| cos(f - a)
  const double margin = 1e-9 * length + 1e-12 * (std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]) +
                                                 std::abs(slab.apex[0]) + std::abs(slab.apex[1]) + std::abs(slab.apex[2]));
  return (cosine < 0.0 ? length : sine) - margin;
}

// The squared distance from p to the node's slab (0 inside), less a margin for the rounding of
// the dot products (relative 1e-12, as kPruneSlack), or with `cones` to its cone where larger: a
// lower bound of the distance to its triangles.
inline double TriangleBvh::slab_distance2(const double* p, int32_t node, bool cones) const {
  const Slab& slab = slabs_[size_t(node)];
  const double d = slab.normal[0] * p[0] + slab.normal[1] * p[1] + slab.normal[2] * p[2];
  double gap = std::max(slab.lo - d, d - slab.hi) - 1e-12 * (std::abs(d) + std::abs(slab.lo) + std::abs(slab.hi));
  if (cones && slab.cos_half > -1.0) gap = std::max(gap, cone_gap(p, slab));
  return gap > 0.0 ? gap * gap : 0.0;
}

int32_t TriangleBvh::build(int32_t begin, int32_t end, int32_t index, const std::vector<double>& corners,
                           BuildItem* items) {
  // Median split along the longest axis of the centroids' box: a balanced tree, built in
  // O(m log m), that serves nearest-point queries well. Boxes come from the children, so each
  // triangle's corners are read once. Nodes in depth-first order: a node's left child follows it.
  int32_t next = index + 1;
  Node node{};
  if (end - begin <= kLeafSize) {
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = std::numeric_limits<double>::infinity();
      node.hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (int32_t i = begin; i < end; ++i)
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) {
          node.lo[k] = std::min(node.lo[k], corners[9 * size_t(items[i].id) + 3 * c + k]);
          node.hi[k] = std::max(node.hi[k], corners[9 * size_t(items[i].id) + 3 * c + k]);
        }
    node.first = begin;
    node.count = end - begin;
  } else {
    double centre_lo[3], centre_hi[3];
    for (int k = 0; k < 3; ++k) {
      centre_lo[k] = std::numeric_limits<double>::infinity();
      centre_hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (int32_t i = begin; i < end; ++i)
      for (int k = 0; k < 3; ++k) {
        centre_lo[k] = std::min(centre_lo[k], items[i].centroid[k]);
        centre_hi[k] = std::max(centre_hi[k], items[i].centroid[k]);
      }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (centre_hi[k] - centre_lo[k] > centre_hi[axis] - centre_lo[axis]) axis = k;
    const int32_t middle = begin + (end - begin) / 2;
    std::nth_element(items + begin, items + middle, items + end, [axis](const BuildItem& x, const BuildItem& y) {
      return x.centroid[axis] < y.centroid[axis] || (x.centroid[axis] == y.centroid[axis] && x.id < y.id);
    });
    const int32_t left = index + 1;
    int32_t right;
    if (index == 0 && end - begin >= kParallelBuild) {  // the same tree, its halves side by side
      right = left + subtree_nodes(middle - begin);
      parallel_invoke(true, [&] { build(begin, middle, left, corners, items); },
                      [&] { next = build(middle, end, right, corners, items); });
    } else {
      right = build(begin, middle, left, corners, items);
      next = build(middle, end, right, corners, items);
    }
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = std::min(nodes_[left].lo[k], nodes_[right].lo[k]);
      node.hi[k] = std::max(nodes_[left].hi[k], nodes_[right].hi[k]);
    }
    node.first = right;
    node.count = 0;
  }
  nodes_[index] = node;
  return next;
}

ClosestHit TriangleBvh::closest(const double* p, int32_t hint_slot, double within2) const {
  return search<false>(p, hint_slot, within2, nullptr);
}

ClosestHit TriangleBvh::closest_counted(const double* p, int32_t hint_slot, int64_t& tested) const {
  return search<true>(p, hint_slot, -1.0, &tested);
}

// kCounted: the measured triangles are added to *tested (apart, so that the plain lookup, on the
// decimation's hot path, does no counting).
template <bool kCounted>
ClosestHit TriangleBvh::search(const double* p, int32_t hint_slot, double within2, int64_t* tested) const {
  ClosestHit hit;
  hit.distance2 = std::numeric_limits<double>::infinity();
  // A leaf skips a triangle whose corners' box lies beyond skip2: the best hit's distance plus
  // a margin for the rounding of a closest point (a few units in the last place of the
  // coordinates, which may put it outside that box), with the nodes' relative slack.
  const double margin = kSkipMargin * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + coordinate_scale_);
  double skip2 = std::numeric_limits<double>::infinity();
  // The triangle test has internal linkage so that it is called directly, not through the shared
  // module's PLT as the exported closest_point_on_triangle is.
  auto consider = [&](int32_t slot) {
    if constexpr (kCounted) ++*tested;
    double q[3];
    const double* t = &corners_[9 * size_t(slot)];
    const double d2 = triangle_distance2(p, t, t + 3, t + 6, q);
    if (d2 < hit.distance2 || (d2 == hit.distance2 && triangle_ids_[slot] < hit.triangle)) {
      hit.distance2 = d2;
      hit.triangle = triangle_ids_[slot];
      hit.slot = slot;
      for (int k = 0; k < 3; ++k) hit.point[k] = q[k];
      const double reach = std::sqrt(d2) + margin;
      skip2 = reach * reach * kPruneSlack;
    }
  };
  if (hint_slot >= 0 && hint_slot < int32_t(triangle_ids_.size())) consider(hint_slot);

  // Depth first, nearer child first: the walk goes straight down into the nearer child and keeps
  // the farther one on the stack, which visits the nodes in the same order as pushing both.
  struct Entry {
    int32_t node;
    double distance2;
  };
  Entry stack[128];
  int depth = 0;
  // With slabs (slivers' fans), an exact query orders and prunes nodes by the larger of the box's
  // and the slab's distance: the slivers' boxes all hold p, so the boxes alone would not tell the
  // near ones. (The answer does not depend on the order.) A query that stops `within2` keeps the
  // boxes' order, which decides the hit it stops at; the slabs only prune nodes that hold no
  // triangle as near as the best hit, so it finds the same hits.
  // The counted lookups (the brackets', whose budgets count the triangles measured) leave the
  // cones out: there, fewer triangles a lookup spent the same budget on more lookups, each with
  // its bracket's own work, for the same result (docs/bench_notes/high-valence.md).
  const bool slabs = !slabs_.empty(), slab_order = slabs && !(within2 >= 0.0), cones = !kCounted;
  auto bound = [&](int32_t i) {
    const double box = box_distance2(p, nodes_[i].lo, nodes_[i].hi);
    return slab_order ? std::max(box, slab_distance2(p, i, cones)) : box;
  };
  auto slab_keeps = [&](const Entry& e, double reach) {
    return !slabs || slab_order || !(slab_distance2(p, e.node, cones) > reach);
  };
  Entry entry{0, bound(0)};
  for (;;) {
    if (hit.distance2 <= within2) break;
    if (!(entry.distance2 > hit.distance2 * kPruneSlack) && slab_keeps(entry, hit.distance2 * kPruneSlack)) {
      const Node& node = nodes_[entry.node];
      if (node.count > 0) {
        // A triangle farther by its own box than the best hit, or the hint (measured first),
        // cannot change the hit; the counted lookups count it all the same (their budgets).
        for (int32_t s = node.first; s < node.first + node.count; ++s)
          if (s != hint_slot && !(corner_box_distance2(p, &corners_[9 * size_t(s)]) > skip2))
            consider(s);
          else if constexpr (kCounted)
            ++*tested;
      } else {
        const int32_t left = entry.node + 1, right = node.first;
        const double dl = bound(left), dr = bound(right);
        const Entry nearer = dl <= dr ? Entry{left, dl} : Entry{right, dr};
        const Entry farther = dl <= dr ? Entry{right, dr} : Entry{left, dl};
        const double reach = hit.distance2 * kPruneSlack;
        if (farther.distance2 <= reach && slab_keeps(farther, reach)) stack[depth++] = farther;
        if (nearer.distance2 <= reach && slab_keeps(nearer, reach)) {
          entry = nearer;
          continue;
        }
      }
    }
    if (depth == 0) break;
    entry = stack[--depth];
  }
  return hit;
}

}  // namespace topstoc
