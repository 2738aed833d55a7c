// The BVH query against a plain reference walk over the same tree (push both children, farther
// first; scalar box distances; the exported point-triangle distance): the hit's bits (distance,
// point, triangle, slot) must be the same for every hint and stop distance, since the walk's order
// decides which triangle a query with a stop distance returns.
#include <doctest/doctest.h>

#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "meshes.hpp"
#include "topstoc/distance/bvh.hpp"

using topstoc::ClosestHit;
using topstoc::TriangleBvh;

namespace {

double reference_box_distance2(const double* p, const TriangleBvh::Node& n) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double below = n.lo[k] - p[k], above = p[k] - n.hi[k];
    const double d = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
    d2 += d * d;
  }
  return d2;
}

ClosestHit reference_closest(const TriangleBvh& bvh, const double* p, int32_t hint, double within2) {
  const double slack = 1.0 + 1e-12;
  ClosestHit hit;
  hit.distance2 = std::numeric_limits<double>::infinity();
  auto consider = [&](int32_t slot) {
    double q[3];
    const double* t = bvh.slot_corners(slot);
    const double d2 = topstoc::closest_point_on_triangle(p, t, t + 3, t + 6, q);
    if (d2 < hit.distance2 || (d2 == hit.distance2 && bvh.slot_triangle(slot) < hit.triangle)) {
      hit.distance2 = d2, hit.triangle = bvh.slot_triangle(slot), hit.slot = slot;
      for (int k = 0; k < 3; ++k) hit.point[k] = q[k];
    }
  };
  if (hint >= 0 && hint < bvh.num_triangles()) consider(hint);
  std::vector<std::pair<int32_t, double>> stack{{0, reference_box_distance2(p, bvh.node(0))}};
  while (!stack.empty() && !(hit.distance2 <= within2)) {
    const auto [index, distance2] = stack.back();
    stack.pop_back();
    if (distance2 > hit.distance2 * slack) continue;
    const TriangleBvh::Node& node = bvh.node(index);
    if (node.count > 0) {
      for (int32_t s = node.first; s < node.first + node.count; ++s) consider(s);
      continue;
    }
    const int32_t left = index + 1, right = node.first;
    const double dl = reference_box_distance2(p, bvh.node(left)), dr = reference_box_distance2(p, bvh.node(right));
    const std::pair<int32_t, double> nearer{dl <= dr ? left : right, dl <= dr ? dl : dr};
    const std::pair<int32_t, double> farther{dl <= dr ? right : left, dl <= dr ? dr : dl};
    if (farther.second <= hit.distance2 * slack) stack.push_back(farther);
    if (nearer.second <= hit.distance2 * slack) stack.push_back(nearer);
  }
  return hit;
}

bool same_bits(const ClosestHit& a, const ClosestHit& b) {
  return std::memcmp(&a.distance2, &b.distance2, sizeof(double)) == 0 &&
         std::memcmp(a.point, b.point, sizeof(a.point)) == 0 && a.triangle == b.triangle && a.slot == b.slot;
}

}  // namespace

TEST_CASE("BVH query equals the reference walk bit for bit, with hints and stop distances") {
  const topstoc_test::Arrays mesh = topstoc_test::torus(40, 23);
  const TriangleBvh bvh(mesh.positions.data(), mesh.triangles.data(), mesh.num_triangles());
  std::mt19937 random(23);
  std::uniform_real_distribution<double> unit(0.0, 1.0), coordinate(-3.5, 3.5);
  const int32_t m = int32_t(bvh.num_triangles());
  int32_t hint = -1, mismatches = 0, queries = 0;
  for (int probe = 0; probe < 3000; ++probe) {
    double p[3];
    if (probe % 3 == 0) {  // a point of the surface itself: corners, edges and ties between triangles
      const double* t = bvh.slot_corners(int32_t(random() % m));
      const double u = probe % 2 ? 0.0 : unit(random), v = (1 - u) * (probe % 5 ? unit(random) : 0.0);
      for (int k = 0; k < 3; ++k) p[k] = t[k] + u * (t[3 + k] - t[k]) + v * (t[6 + k] - t[k]);
    } else if (probe % 3 == 1) {  // near the surface
      const double* t = bvh.slot_corners(int32_t(random() % m));
      for (int k = 0; k < 3; ++k) p[k] = t[k] + 0.05 * coordinate(random);
    } else {
      for (double& x : p) x = coordinate(random);
    }
    for (const double within : {-1.0, 0.0, 1e-3, 0.2}) {
      const double within2 = within >= 0 ? within * within : -1.0;
      for (const int32_t h : {int32_t(-1), hint}) {
        ++queries;
        if (!same_bits(bvh.closest(p, h, within2), reference_closest(bvh, p, h, within2))) ++mismatches;
      }
    }
    hint = probe % 4 ? bvh.closest(p, hint).slot : int32_t(random() % m);
  }
  CHECK(queries == 24000);
  CHECK(mismatches == 0);
}
