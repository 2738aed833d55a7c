// The max's bracket (bounded_max.hpp) depends on a surface's triangles and corner positions,
// not on how its vertices are numbered or on vertices no triangle uses: the tiny-budget fit
// (decimate/tiny_fit.cpp) measures its result with only the live vertices, numbered apart,
// and must get the brackets it got with the collapser's numbering.
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "distance/bounded_max.hpp"
#include "meshes.hpp"

using topstoc::MaxBracket;
using topstoc::Surface;

namespace {

// A coarse torus, its vertices jittered off the fine one, numbered at random among unused
// vertices (as a collapser's survivors are), and the same triangles with only the used vertices
// numbered in first-use order.
struct TwoNumberings {
  Surface scattered, compact;
};

TwoNumberings coarse_torus(int32_t n, int32_t m, unsigned seed) {
  const topstoc_test::Arrays a = topstoc_test::torus(n, m);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  std::vector<double> moved = a.positions;
  for (double& x : moved) x += jitter(random);
  const int32_t vertices = int32_t(moved.size() / 3), spread = 5 * vertices;
  std::vector<int32_t> slot(spread);
  std::iota(slot.begin(), slot.end(), 0);
  std::shuffle(slot.begin(), slot.end(), random);
  std::vector<double> scattered(3 * size_t(spread), 7.0);  // unused vertices far away
  for (int32_t v = 0; v < vertices; ++v) std::copy_n(&moved[3 * size_t(v)], 3, &scattered[3 * size_t(slot[v])]);
  std::vector<int32_t> scattered_triangles, compact_triangles, index(vertices, -1);
  std::vector<double> compact;
  for (int32_t v : a.triangles) {
    scattered_triangles.push_back(slot[v]);
    if (index[v] < 0) index[v] = int32_t(compact.size() / 3), compact.insert(compact.end(), &moved[3 * size_t(v)], &moved[3 * size_t(v)] + 3);
    compact_triangles.push_back(index[v]);
  }
  return {Surface(std::move(scattered), std::move(scattered_triangles)), Surface(std::move(compact), std::move(compact_triangles))};
}

void check_same(const MaxBracket& a, const MaxBracket& b) {
  CHECK(a.lower == b.lower);
  CHECK(a.upper == b.upper);
  CHECK(a.queries == b.queries);
  CHECK(a.lower_triangle == b.lower_triangle);
  CHECK(a.converged == b.converged);
  for (int k = 0; k < 3; ++k) CHECK(a.lower_point[k] == b.lower_point[k]);
}

}  // namespace

TEST_CASE("the max's bracket is the same for a surface numbered two ways, both directions, with and without a threshold") {
  const topstoc_test::Arrays fine_arrays = topstoc_test::torus(96, 48);
  const Surface fine(fine_arrays.positions, fine_arrays.triangles);
  for (unsigned seed : {1u, 2u, 3u}) {
    const TwoNumberings coarse = coarse_torus(12 + int32_t(seed), 8, seed);
    const MaxBracket there = bound_max_distance_by_tree(coarse.compact, fine, 1e-2);
    const MaxBracket back = bound_max_distance_by_tree(fine, coarse.compact, 1e-2);
    REQUIRE(there.lower > 0.01);  // the jitter lifts the coarse torus off the fine one
    REQUIRE(back.queries > 100);  // a search, not a settled root
    check_same(there, bound_max_distance_by_tree(coarse.scattered, fine, 1e-2));
    check_same(back, bound_max_distance_by_tree(fine, coarse.scattered, 1e-2));
    for (double threshold : {0.5 * there.lower, there.upper}) {
      check_same(bound_max_distance_by_tree(coarse.compact, fine, 1e-2, 4000000, threshold),
                 bound_max_distance_by_tree(coarse.scattered, fine, 1e-2, 4000000, threshold));
      check_same(bound_max_distance_by_tree(fine, coarse.compact, 1e-2, 4000000, threshold),
                 bound_max_distance_by_tree(fine, coarse.scattered, 1e-2, 4000000, threshold));
    }
  }
}
