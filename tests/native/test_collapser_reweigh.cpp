// Collapser::reweigh: a copy of a collapser taken part-way continues under new cost weights (the
// max-aware refinement's reruns), keeping more vertices where the weights are high.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "decimate/collapser.hpp"
#include "collapse_setup.hpp"
#include "meshes.hpp"

using topstoc::Collapser;
using topstoc_test::torus_setup;

namespace {

// Live vertices of `c` with x > 0.
int32_t alive_on_positive_side(const Collapser& c) {
  int32_t count = 0;
  for (int32_t v = 0; v < c.vertices(); ++v) count += c.vertex_alive(v) && c.position(v)[0] > 0.0;
  return count;
}

}  // namespace

TEST_CASE("a reweighed copy keeps more vertices where the weights grew") {
  const auto mesh = topstoc_test::torus(40, 20, 0.6, 0.25);  // inside [-1, 1], as normalised positions are
  const int32_t n = int32_t(mesh.positions.size() / 3);
  std::vector<int32_t> triangles = mesh.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  Collapser first(triangles, corners, torus_setup(mesh));
  first.run({n / 2, 0});
  // Both copies work on the same arrays, as in the refinement: each gets the state at the copy.
  const Collapser at_copy(first);
  const std::vector<int32_t> copy_triangles = triangles, copy_corners = corners;

  Collapser even(at_copy);
  even.reweigh(std::vector<double>(n, 1.0));
  even.run({n / 8, 0});
  const int32_t even_positive = alive_on_positive_side(even);

  triangles = copy_triangles;
  corners = copy_corners;
  Collapser heavy(at_copy);
  std::vector<double> weight(n, 1.0);
  for (int32_t v = 0; v < n; ++v)
    if (mesh.positions[3 * size_t(v)] > 0.0) weight[v] = 100.0;
  heavy.reweigh(weight);
  heavy.run({n / 8, 0});
  const int32_t heavy_positive = alive_on_positive_side(heavy);

  int32_t even_alive = 0, heavy_alive = 0;
  for (int32_t v = 0; v < n; ++v) even_alive += even.vertex_alive(v), heavy_alive += heavy.vertex_alive(v);
  CHECK(even_alive == n / 8);
  CHECK(heavy_alive == n / 8);
  // The even copy keeps about half its vertices on each side of the symmetric torus; the heavy one
  // takes its collapses from the light side first.
  CHECK(even_positive > n / 8 / 3);
  CHECK(even_positive < 2 * n / 8 / 3);
  CHECK(heavy_positive > 3 * (n / 8) / 4);
}
