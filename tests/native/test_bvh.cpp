// BVH closest points against a brute-force scan over every triangle; the point-triangle
// distance itself against a dense sampling of the triangle.
#include <doctest/doctest.h>

#include <random>
#include <vector>

#include "topstoc/distance/bvh.hpp"

using topstoc::closest_point_on_triangle;
using topstoc::TriangleBvh;

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
