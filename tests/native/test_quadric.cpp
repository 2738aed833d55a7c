// Quadric error (Garland & Heckbert) against the brute-force area-weighted sum of squared
// point-plane distances.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "decimate/quadric.hpp"

using topstoc::Quadric;

namespace {

double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Area times the squared distance of x to the plane of the triangle (0 for zero area).
double brute_error(const double* p0, const double* p1, const double* p2, const double* x) {
  const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  const double w[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  const double twice_area = std::sqrt(dot(n, n));
  if (twice_area == 0) return 0;
  const double d[3] = {x[0] - p0[0], x[1] - p0[1], x[2] - p0[2]};
  const double distance = dot(d, n) / twice_area;
  return 0.5 * twice_area * distance * distance;
}

}  // namespace

TEST_CASE("quadric error equals the area-weighted sum of squared plane distances") {
  std::mt19937 random(13);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  for (int round = 0; round < 50; ++round) {
    const int count = 1 + int(random() % 12);
    std::vector<double> corners(9 * count);
    for (double& c : corners) c = coordinate(random);
    if (round % 5 == 0) std::copy(corners.begin(), corners.begin() + 3, corners.begin() + 3);  // zero area
    Quadric sum, first_half, second_half;
    for (int t = 0; t < count; ++t) {
      const double* p = &corners[9 * t];
      sum.add_triangle(p, p + 3, p + 6);
      (t < count / 2 ? first_half : second_half).add_triangle(p, p + 3, p + 6);
    }
    first_half.add(second_half);  // adding quadrics adds their planes
    for (int probe = 0; probe < 20; ++probe) {
      const double x[3] = {coordinate(random), coordinate(random), coordinate(random)};
      double expected = 0;
      for (int t = 0; t < count; ++t) expected += brute_error(&corners[9 * t], &corners[9 * t + 3], &corners[9 * t + 6], x);
      CHECK(sum.error(x) == doctest::Approx(expected).epsilon(1e-9).scale(1.0));
      CHECK(first_half.error(x) == doctest::Approx(expected).epsilon(1e-9).scale(1.0));
    }
  }
}

TEST_CASE("a quadric is zero on its planes and ignores zero-area triangles") {
  const double a[3] = {0, 0, 1}, b[3] = {3, 0, 1}, c[3] = {0, 2, 1};
  Quadric q;
  q.add_triangle(a, b, c);
  const double on_plane[3] = {7, -4, 1}, above[3] = {1, 1, 3};
  CHECK(q.error(on_plane) == doctest::Approx(0.0).scale(1.0));
  CHECK(q.error(above) == doctest::Approx(3.0 * 4.0));  // area 3, distance 2
  Quadric flat;
  flat.add_triangle(a, b, b);
  CHECK(flat.error(above) == 0.0);
}
