// The tiny fit's brackets stop at their query budgets (tiny_fit.cpp kFitQueriesPerTriangle for
// the whole fit, kSideQueriesPerTriangle for one side of one bracket): on a cylinder with fanned
// caps, whose slivers made each bracket cost hundreds of queries a triangle, the fit of a
// 252-triangle result had taken 9.5M queries for 2,560 input triangles, and each side of a
// bracket on one of 2,000 segments ran to 2M queries (32M triangles measured) unconverged.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "collapse_setup.hpp"
#include "core/portable.hpp"
#include "decimate/collapser.hpp"
#include "decimate/tiny_fit.hpp"
#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace {

// A cylinder of radius 0.4 and height 0.8 around the origin, `rows` rows of `segments` quads,
// each cap a fan from its centre.
topstoc_test::Arrays fanned_cylinder(int32_t segments, int32_t rows) {
  topstoc_test::Arrays a;
  for (int32_t r = 0; r <= rows; ++r)
    for (int32_t i = 0; i < segments; ++i) {
      const double t = 2.0 * topstoc::kPi * i / segments;
      a.positions.insert(a.positions.end(), {0.4 * std::cos(t), 0.4 * std::sin(t), -0.4 + 0.8 * r / rows});
    }
  const int32_t bottom = int32_t(a.positions.size() / 3), top = bottom + 1;
  a.positions.insert(a.positions.end(), {0.0, 0.0, -0.4, 0.0, 0.0, 0.4});
  for (int32_t r = 0; r < rows; ++r)
    for (int32_t i = 0; i < segments; ++i) {
      const int32_t j = (i + 1) % segments, a0 = r * segments + i, a1 = r * segments + j;
      const int32_t b0 = a0 + segments, b1 = a1 + segments;
      a.triangles.insert(a.triangles.end(), {a0, a1, b1, a0, b1, b0});
    }
  for (int32_t i = 0; i < segments; ++i) {
    const int32_t j = (i + 1) % segments;
    a.triangles.insert(a.triangles.end(), {bottom, j, i, top, rows * segments + i, rows * segments + j});
  }
  return a;
}

// The fit of a fanned cylinder's decimation to `faces` triangles.
topstoc::TinyFit fit_cylinder(int32_t segments, int32_t faces) {
  const auto arrays = fanned_cylinder(segments, 4);
  const int64_t m = arrays.num_triangles();
  const topstoc::Mesh mesh(arrays.positions, arrays.triangles.data(), m);
  // The collapser on the mesh's own numbering, in coordinates that need no normalising.
  topstoc_test::Arrays own;
  own.positions.assign(mesh.positions().begin(), mesh.positions().end());
  own.triangles.assign(mesh.faces().begin(), mesh.faces().end());
  std::vector<int32_t> triangles = own.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  topstoc::Collapser collapser(triangles, corners, topstoc_test::torus_setup(own));
  collapser.run({0, faces});
  REQUIRE(collapser.live_faces() <= 400);
  const topstoc::Surface input(own.positions, own.triangles);
  return topstoc::fit_tiny(mesh, collapser, 4, true, input, -1.0);
}

}  // namespace

TEST_CASE("the fit of a fan of slivers stops at its query budget") {
  const topstoc::TinyFit fit = fit_cylinder(256, 252);
  // The budget is checked before each bracket, and a bracket's two sides take it at most.
  const int64_t budget = 300 * 2560;
  CHECK(fit.queries > 0);
  CHECK(fit.queries <= 2 * budget);
  CHECK(fit.after2 <= fit.before2);
}

TEST_CASE("one side of a fit's bracket among slivers stops at its own budget") {
  const topstoc::TinyFit fit = fit_cylinder(2000, 196);
  // A side: at most 8 queries per input triangle (20,000 here) and 16 times that many triangles
  // measured (counted one query per 16), the last query's triangles past it at most.
  const int64_t side = 8 * 20000, slack = 20000 / 16;
  REQUIRE(fit.brackets > 0);
  CHECK(fit.queries <= int64_t(fit.brackets) * 2 * (2 * side + slack));
  CHECK(fit.after2 <= fit.before2);
}
