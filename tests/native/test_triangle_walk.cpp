// The walk over a surface's triangles toward a point (triangle_walk.hpp) against a tree lookup: the
// distance it returns is the one to the triangle it ends on, never below the surface's distance,
// that distance itself over a flat sheet and near a smooth torus from a neighbour's triangle, near
// it beyond a border, and a walk cut short says so.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "distance/triangle_walk.hpp"
#include "distance/vertex_stars.hpp"
#include "meshes.hpp"
#include "topstoc/distance/bvh.hpp"
#include "topstoc/distance/hausdorff.hpp"

using topstoc::Surface;
using topstoc::TriangleWalk;

namespace {

double distance2_to(const Surface& s, int32_t f, const double* x) {
  const auto& p = s.positions();
  const int32_t* c = &s.triangles()[3 * size_t(f)];
  double closest[3];
  return topstoc::closest_point_on_triangle(x, &p[3 * size_t(c[0])], &p[3 * size_t(c[1])], &p[3 * size_t(c[2])],
                                            closest);
}

// A point on triangle f at barycentric (u, v), lifted by `lift` along +z.
std::vector<double> point_on(const Surface& s, int32_t f, double u, double v, double lift) {
  const auto& p = s.positions();
  const int32_t* c = &s.triangles()[3 * size_t(f)];
  std::vector<double> x(3);
  for (int k = 0; k < 3; ++k)
    x[k] = (1 - u - v) * p[3 * size_t(c[0]) + k] + u * p[3 * size_t(c[1]) + k] + v * p[3 * size_t(c[2]) + k];
  x[2] += lift;
  return x;
}

// A surface with the triangles around its vertices and a walk over it.
struct Walkable {
  Surface surface;
  topstoc::Stars stars;
  TriangleWalk walker;
  explicit Walkable(topstoc_test::Arrays a)
      : surface(std::move(a.positions), std::move(a.triangles)), stars(surface), walker(surface, stars) {}
};

// Checks what every walk's end must be (its distance that of its triangle, never under the
// surface's) and returns the surface's squared distance by a lookup.
double checked(const Surface& s, const TriangleWalk::End& end, const double* x) {
  const double exact2 = s.bvh().closest(x).distance2;
  CHECK(end.distance2 == distance2_to(s, end.triangle, x));
  CHECK(end.distance2 >= exact2);
  return exact2;
}

}  // namespace

TEST_CASE("on a flat sheet a walk from any triangle within reach ends at the distance of a lookup") {
  const Walkable sheet(topstoc_test::grid(30, 30));
  std::mt19937 random(7);
  std::uniform_int_distribution<int32_t> any(0, sheet.surface.num_triangles() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int settled = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int32_t target = any(random), start = any(random);
    double u = unit(random), v = unit(random);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const std::vector<double> x = point_on(sheet.surface, target, u, v, 0.5 * (unit(random) - 0.5));
    const TriangleWalk::End end = sheet.walker.walk(x.data(), start, 200, 0.0);
    const double exact2 = checked(sheet.surface, end, x.data());
    if (end.settled) {
      ++settled;
      CHECK(end.distance2 == doctest::Approx(exact2).epsilon(1e-12));
    }
  }
  CHECK(settled == 2000);  // 60 steps cross the sheet
}

TEST_CASE("on a torus a walk from a neighbouring point's triangle finds the nearest, inside and outside") {
  // Points within a tenth of the tube's radius off the surface, each walked from the triangle a
  // lookup gives for a point a few triangles away.
  const Walkable walkable(topstoc_test::torus(96, 48));
  const Surface& torus = walkable.surface;
  std::mt19937 random(11);
  std::uniform_int_distribution<int32_t> any(0, torus.num_triangles() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int exact = 0;
  const int trials = 3000;
  for (int trial = 0; trial < trials; ++trial) {
    const int32_t target = any(random);
    const std::vector<double> on = point_on(torus, target, 0.3 * unit(random), 0.3 * unit(random), 0.0);
    // off the surface along the tube's normal (from the tube's centre circle through the point)
    const double r = std::hypot(on[0], on[1]);
    const double centre[3] = {2.0 * on[0] / r, 2.0 * on[1] / r, 0.0};
    const double lift = 0.07 * (2 * unit(random) - 1);
    std::vector<double> x(3), nearby(3);
    for (int k = 0; k < 3; ++k) {
      const double n = (on[k] - centre[k]) / 0.7;
      x[k] = on[k] + lift * n;
      nearby[k] = x[k] + 0.15 * (unit(random) - 0.5);
    }
    const int32_t start = torus.bvh().closest(nearby.data()).triangle;
    const TriangleWalk::End end = walkable.walker.walk(x.data(), start, 16, 0.0);
    const double exact2 = checked(torus, end, x.data());
    CHECK(end.settled);
    exact += end.distance2 <= exact2 * (1 + 1e-9) + 1e-24;
  }
  CHECK(exact >= trials * 99 / 100);
}

TEST_CASE("a point beyond a sheet's border walks along it to within a side's length of the nearest") {
  // The walk does not step off a border; along it the edge neighbours lead to the nearest triangle
  // or to one with a corner on the nearest side (their distances are the lookup's up to that side).
  const Walkable sheet(topstoc_test::grid(10, 10));
  for (const std::vector<double>& x : {std::vector<double>{-2.0, 4.3, 0.5}, std::vector<double>{12.0, 12.5, -1.0},
                                       std::vector<double>{5.5, -0.25, 0.0}, std::vector<double>{-0.5, -0.5, 0.0}}) {
    const TriangleWalk::End end = sheet.walker.walk(x.data(), 55, 40, 0.0);
    const double exact = std::sqrt(checked(sheet.surface, end, x.data()));
    CHECK(end.settled);
    CHECK(std::sqrt(end.distance2) <= exact + 1.0);
  }
}

TEST_CASE("a walk out of steps says so, and its distance still bounds the surface's") {
  const Walkable sheet(topstoc_test::grid(30, 30));
  const double x[3] = {29.5, 29.5, 0.1};
  const TriangleWalk::End end = sheet.walker.walk(x, 0, 3, 0.0);  // from the far corner of the sheet
  CHECK_FALSE(end.settled);
  CHECK(end.distance2 > checked(sheet.surface, end, x));
}

TEST_CASE("a walk that ends within `close` of the point skips the steps to nearer neighbours") {
  // Over a triangle of a sheet folded 90 degrees along a line, next to the fold: the triangle under
  // the point along its own normal is not the nearest. With `close` above that triangle's
  // distance, the walk stops there; with 0 it goes on to the nearest.
  topstoc_test::Arrays folded = topstoc_test::grid(8, 8);
  for (size_t i = 0; i < folded.positions.size(); i += 3)
    if (folded.positions[i] > 4.0) folded.positions[i + 2] = -(folded.positions[i] - 4.0), folded.positions[i] = 4.0;
  const Walkable sheet(folded);
  const double x[3] = {4.0, 3.5, -0.25};  // on the folded part, a quarter below the fold
  const int32_t start = 2 * (3 * 8 + 3);  // a triangle of the flat part near the fold
  const TriangleWalk::End far = sheet.walker.walk(x, start, 20, 1.0);
  const TriangleWalk::End near = sheet.walker.walk(x, start, 20, 0.0);
  CHECK(near.distance2 == doctest::Approx(0.0));
  CHECK(far.distance2 >= near.distance2);
  CHECK(far.distance2 <= 1.0);
}
