// BVH closest points against a brute-force scan over every triangle; the point-triangle
// distance itself against a dense sampling of the triangle.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "topstoc/distance/bvh.hpp"
#include "with_threads.hpp"

using topstoc::closest_point_on_triangle;
using topstoc::TriangleBvh;

namespace {

// A mesh as positions and vertex triples, with the points the fan tests probe it at and the
// brute-force answer there.
struct Indexed {
  std::vector<double> positions;
  std::vector<int32_t> triangles;

  int32_t size() const { return int32_t(triangles.size() / 3); }
  const double* corner(int32_t t, int c) const { return &positions[3 * size_t(triangles[3 * size_t(t) + c])]; }

  // A point of triangle t inside it (kind 0), on an edge (1) or at a vertex (2), or moved off it
  // by up to 1e-6, 0.05 or 3 (kinds 3-5).
  void probe(std::mt19937& random, int32_t t, int kind, double p[3]) const {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double w[3] = {unit(random), unit(random), unit(random)};
    if (kind == 1) w[2] = 0.0;
    if (kind == 2) w[1] = w[2] = 0.0;
    const double sum = w[0] + w[1] + w[2];
    for (int k = 0; k < 3; ++k) p[k] = (w[0] * corner(t, 0)[k] + w[1] * corner(t, 1)[k] + w[2] * corner(t, 2)[k]) / sum;
    const double scale = kind == 3 ? 1e-6 : kind == 4 ? 0.05 : kind == 5 ? 3.0 : 0.0;
    for (int k = 0; k < 3; ++k) p[k] += scale * (unit(random) - 0.5);
  }

  // The smallest squared distance from p over every triangle, and the lowest id at it.
  std::pair<double, int32_t> nearest(const double* p) const {
    double best = 1e300;
    int32_t best_triangle = -1;
    for (int32_t f = 0; f < size(); ++f) {
      double q[3];
      const double d2 = closest_point_on_triangle(p, corner(f, 0), corner(f, 1), corner(f, 2), q);
      if (d2 < best) best = d2, best_triangle = f;  // strict: the lowest id wins ties
    }
    return {best, best_triangle};
  }
};

}  // namespace

TEST_CASE("closest point on a triangle is no farther than any point of a dense sampling, and on it") {
  std::mt19937 random(17);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int round = 0; round < 200; ++round) {
    double t[9], p[3], q[3];
    for (double& c : t) c = coordinate(random);
    if (round % 10 == 0) std::copy(t, t + 3, t + 3);  // repeated corner: a segment
    for (double& c : p) c = 2 * coordinate(random);
    const double d2 = closest_point_on_triangle(p, t, t + 3, t + 6, q);
    CHECK(d2 == doctest::Approx((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                (p[2] - q[2]) * (p[2] - q[2])));
    const int steps = 60;
    double best = 1e300;
    for (int i = 0; i <= steps; ++i)
      for (int j = 0; i + j <= steps; ++j) {
        const double u = double(i) / steps, v = double(j) / steps, w = 1 - u - v;
        double s2 = 0;
        for (int k = 0; k < 3; ++k) {
          const double x = w * t[k] + u * t[3 + k] + v * t[6 + k] - p[k];
          s2 += x * x;
        }
        best = std::min(best, s2);
      }
    CHECK(d2 <= best + 1e-12);
    CHECK(d2 >= best - 0.05 * std::sqrt(best) - 1e-3);  // the sampling's spacing bounds the gap
  }
}

TEST_CASE("BVH closest point equals the brute-force minimum over all triangles, whatever the hint") {
  std::mt19937 random(19);
  std::uniform_real_distribution<double> coordinate(-5.0, 5.0), offset(-0.6, 0.6);
  const int32_t num_triangles = 400, num_vertices = 3 * num_triangles;
  std::vector<double> positions(3 * num_vertices);
  for (int32_t t = 0; t < num_triangles; ++t) {  // small triangles scattered in a box, some degenerate
    double centre[3] = {coordinate(random), coordinate(random), coordinate(random)};
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) positions[9 * t + 3 * c + k] = centre[k] + (t % 37 == 0 ? 0.0 : offset(random));
  }
  std::vector<int32_t> triangles(3 * num_triangles);
  for (int32_t i = 0; i < 3 * num_triangles; ++i) triangles[i] = i;
  const TriangleBvh bvh(positions.data(), triangles.data(), num_triangles);
  CHECK(bvh.num_triangles() == num_triangles);
  int32_t hint = -1;
  for (int probe = 0; probe < 500; ++probe) {
    const double p[3] = {1.5 * coordinate(random), 1.5 * coordinate(random), 1.5 * coordinate(random)};
    double best = 1e300;
    int32_t best_triangle = -1;
    for (int32_t t = 0; t < num_triangles; ++t) {
      double q[3];
      const double d2 = closest_point_on_triangle(p, &positions[9 * t], &positions[9 * t + 3], &positions[9 * t + 6], q);
      if (d2 < best) best = d2, best_triangle = t;  // strict: the lowest id wins ties
    }
    const auto hit = bvh.closest(p, hint);
    CHECK(hit.distance2 == best);
    CHECK(hit.triangle == best_triangle);
    const auto cold = bvh.closest(p);
    CHECK(cold.triangle == hit.triangle);
    CHECK(cold.distance2 == hit.distance2);
    hint = int32_t(random() % num_triangles);  // an unrelated hint must not change the answer
  }
}

TEST_CASE("BVH over a fan of slivers (slabs): the brute-force minimum at points on and off it") {
  // A double cone of 3,000 rim vertices (the slivers' boxes all reach the apexes, so the tree
  // orders and prunes by its slabs) and points on its faces, its edges, its vertices, off it
  // and far from it: the closest distance and the lowest-id triangle at it, whatever the hint.
  const int32_t n = 3000;
  Indexed cone;
  for (int32_t i = 0; i < n; ++i) {
    const double a = 2 * 3.141592653589793 * i / n;
    cone.positions.insert(cone.positions.end(), {std::cos(a), std::sin(a), 0.0});
  }
  cone.positions.insert(cone.positions.end(), {0.0, 0.0, 1.0, 0.0, 0.0, -1.0});
  for (int32_t i = 0; i < n; ++i) cone.triangles.insert(cone.triangles.end(), {i, (i + 1) % n, n});
  for (int32_t i = 0; i < n; ++i) cone.triangles.insert(cone.triangles.end(), {(i + 1) % n, i, n + 1});
  const int32_t m = cone.size();
  const TriangleBvh bvh(cone.positions.data(), cone.triangles.data(), m);
  CHECK(bvh.has_slabs());
  std::mt19937 random(23);
  int32_t hint = -1, exact_zero = 0;
  for (int probe = 0; probe < 600; ++probe) {
    const int32_t t = int32_t(random() % m);
    double p[3];
    cone.probe(random, t, probe % 6, p);
    const auto [best, best_triangle] = cone.nearest(p);
    exact_zero += best == 0.0;
    const auto hit = bvh.closest(p, hint);
    CHECK(hit.distance2 == best);
    CHECK(hit.triangle == best_triangle);
    const auto cold = bvh.closest(p);
    CHECK(cold.triangle == best_triangle);
    // A query that stops within a distance: a triangle that near, or the closest when none is.
    const double within2 = 0.5 * best + 1e-9;
    const auto near = bvh.closest(p, -1, within2);
    CHECK((near.distance2 <= within2 || (near.distance2 == best && near.triangle == best_triangle)));
    hint = int32_t(random() % m);
  }
  CHECK(exact_zero > 50);  // the vertices: many triangles at distance 0, the lowest id wins
}

TEST_CASE("BVH over a flat fanned disc (cones): the brute-force minimum at points on and off it") {
  // A disc of 4,000 slivers from one centre: the slabs are the disc's plane, so only the sectors'
  // cones prune in it. Points on its faces, edges and vertices, just off it and far: the closest
  // distance and the lowest-id triangle at it, whatever the hint (the counted lookup, without the
  // cones, the same).
  const int32_t n = 4000;
  Indexed disc;
  for (int32_t i = 0; i < n; ++i) {
    const double a = 2 * 3.141592653589793 * i / n;
    disc.positions.insert(disc.positions.end(), {3.0 + std::cos(a), -2.0 + std::sin(a), 0.5});
    disc.triangles.insert(disc.triangles.end(), {i, (i + 1) % n, n});
  }
  disc.positions.insert(disc.positions.end(), {3.0, -2.0, 0.5});
  const TriangleBvh bvh(disc.positions.data(), disc.triangles.data(), n);
  CHECK(bvh.has_slabs());
  std::mt19937 random(29);
  int32_t hint = -1;
  int64_t tested = 0;
  for (int probe = 0; probe < 600; ++probe) {
    const int32_t t = int32_t(random() % n);
    double p[3];
    disc.probe(random, t, probe % 6, p);
    const auto [best, best_triangle] = disc.nearest(p);
    const auto hit = bvh.closest(p, hint);
    CHECK(hit.distance2 == best);
    CHECK(hit.triangle == best_triangle);
    const auto counted = bvh.closest_counted(p, -1, tested);
    CHECK(counted.triangle == best_triangle);
    hint = int32_t(random() % n);
  }
  CHECK(tested > 0);
}

TEST_CASE("a tree built on two threads is the one built on one, node for node, its boxes holding their triangles") {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const int32_t count : {4095, 4096, 9999, 20000}) {  // below and at kParallelBuild, odd halves
    Indexed mesh;
    for (int32_t f = 0; f < count; ++f) {
      const double centre[3] = {unit(random), unit(random), 0.2 * unit(random)};
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) mesh.positions.push_back(centre[k] + 0.01 * unit(random));
        mesh.triangles.push_back(3 * f + c);
      }
    }
    const TriangleBvh one = with_threads(1, [&] { return TriangleBvh(mesh.positions.data(), mesh.triangles.data(), count); });
    const TriangleBvh two = with_threads(2, [&] { return TriangleBvh(mesh.positions.data(), mesh.triangles.data(), count); });
    REQUIRE(one.num_nodes() == two.num_nodes());
    int32_t leaves = 0;
    for (int32_t i = 0; i < int32_t(one.num_nodes()); ++i) {
      const TriangleBvh::Node &a = one.node(i), &b = two.node(i);
      CHECK(a.first == b.first);
      CHECK(a.count == b.count);
      for (int k = 0; k < 3; ++k) CHECK((a.lo[k] == b.lo[k] && a.hi[k] == b.hi[k]));
      if (a.count == 0) continue;
      leaves += a.count;
      for (int32_t s = a.first; s < a.first + a.count; ++s)
        for (int j = 0; j < 9; ++j) CHECK((a.lo[j % 3] <= one.slot_corners(s)[j] && one.slot_corners(s)[j] <= a.hi[j % 3]));
    }
    CHECK(leaves == count);  // every slot in exactly one leaf
    for (int32_t s = 0; s < count; ++s) CHECK(one.slot_triangle(s) == two.slot_triangle(s));
  }
}
