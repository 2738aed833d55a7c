// The symmetric max bracketed from both surfaces' vertices (bracket_symmetric_max, the batch
// report's default) against closed forms: the bracket holds, settles within the tolerance or
// under the resolution, and is the same on one thread and two.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "meshes.hpp"
#include "topstoc/distance/bvh.hpp"
#include "topstoc/distance/hausdorff.hpp"
#include "with_threads.hpp"

using topstoc::Surface;

namespace {

// An n x n grid of squares over [0, 1]^2, two triangles each, at height z(x, y).
template <class Height>
Surface grid(int n, Height z) {
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) positions.insert(positions.end(), {double(i) / n, double(j) / n, z(i, j)});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      triangles.insert(triangles.end(), {a, b, d, a, d, c});
    }
  return Surface(std::move(positions), std::move(triangles));
}

double symmetric(const topstoc::SymmetricBracket& r, bool upper) {
  return upper ? std::max(r.forward.upper, r.backward.upper) : std::max(r.forward.lower, r.backward.lower);
}

}  // namespace

TEST_CASE("a fine grid and a coarse one lifted by h: every point is h from the other") {
  const Surface fine = grid(32, [](int, int) { return 0.0; });
  const Surface coarse = grid(4, [](int, int) { return 0.03; });
  const topstoc::SymmetricBracket r = topstoc::bracket_symmetric_max(fine, coarse, 0.25, 1e-13, 20000000);
  for (const auto* side : {&r.forward, &r.backward}) {
    CHECK(side->converged);
    CHECK(side->lower <= 0.03 * (1 + 1e-12));
    CHECK(side->upper >= 0.03 * (1 - 1e-12));
    CHECK(side->upper <= 0.03 * 1.25 * (1 + 1e-12));
  }
}

TEST_CASE("a raised vertex: the symmetric max is its height, bracketed within the gap") {
  // One interior vertex of a 20 x 20 grid raised by h: the apex is h from the plane, and no
  // point of either surface is farther from the other.
  const double h = 0.07;
  const Surface flat = grid(20, [](int, int) { return 0.0; });
  const Surface raised = grid(20, [h](int i, int j) { return i == 10 && j == 10 ? h : 0.0; });
  const topstoc::SymmetricBracket r = topstoc::bracket_symmetric_max(flat, raised, 0.25, 1e-13, 20000000);
  CHECK(r.forward.converged);
  CHECK(r.backward.converged);
  CHECK(symmetric(r, false) <= h * (1 + 1e-12));
  CHECK(symmetric(r, true) >= h * (1 - 1e-12));
  CHECK(symmetric(r, true) <= symmetric(r, false) * 1.25 * (1 + 1e-12));
  CHECK(r.backward.lower == doctest::Approx(h).epsilon(1e-12));  // the apex, a vertex, is measured
}

TEST_CASE("surfaces that coincide settle under the resolution, the same on one thread and two") {
  // A coarse grid and a fine one on the same plane: the max is 0 up to rounding; bounds under
  // resolution x the diagonal count as settled.
  const Surface fine = grid(40, [](int, int) { return 0.25; });
  const Surface coarse = grid(5, [](int, int) { return 0.25; });
  const double resolution = 1e-7, floor = resolution * std::sqrt(2.0);
  const auto bracket = [&] { return topstoc::bracket_symmetric_max(fine, coarse, 0.25, resolution, 20000000); };
  const auto one = with_threads(1, bracket);
  const auto two = with_threads(2, bracket);
  CHECK(symmetric(one, true) <= floor * (1 + 1e-12));
  CHECK(symmetric(one, false) >= 0.0);
  for (const auto& [a, b] : {std::pair{one.forward, two.forward}, std::pair{one.backward, two.backward}}) {
    CHECK(a.lower == b.lower);
    CHECK(a.upper == b.upper);
    CHECK(a.queries == b.queries);
  }
}

TEST_CASE("the lower bound is at least every vertex's distance, looked up one by one") {
  // Most vertices are measured by walking from a neighbour's triangle, the ones whose walked
  // distance exceeds the largest looked-up one by a lookup: the lower bound is the vertices' max.
  // A bumpy fine torus against a coarse smooth one, both ways.
  topstoc_test::Arrays bumpy = topstoc_test::torus(90, 40);
  for (size_t v = 0; v < bumpy.positions.size() / 3; ++v) {
    double* p = &bumpy.positions[3 * v];
    const double bump = 1.0 + 0.02 * std::sin(7.0 * std::atan2(p[1], p[0])) * std::cos(5.0 * p[2]);
    for (int k = 0; k < 3; ++k) p[k] *= bump;
  }
  const Surface fine(bumpy.positions, bumpy.triangles);
  const topstoc_test::Arrays smooth = topstoc_test::torus(18, 9);
  const Surface coarse(smooth.positions, smooth.triangles);
  const topstoc::SymmetricBracket r = topstoc::bracket_symmetric_max(fine, coarse, 0.25, 1e-7, 20000000);
  CHECK(r.forward.queries < fine.num_vertices() / 100);  // walks, not a lookup a vertex
  for (const auto& [from, to, side] : {std::tuple{&fine, &coarse, &r.forward}, std::tuple{&coarse, &fine, &r.backward}}) {
    double largest = 0.0;
    for (int32_t v = 0; v < from->num_vertices(); ++v)
      largest = std::max(largest, std::sqrt(to->bvh().closest(&from->positions()[3 * size_t(v)]).distance2));
    CHECK(side->lower >= largest);
    CHECK(side->upper >= side->lower);
    CHECK(side->converged);
  }
}
