// The collapser's kept state at wide vertices (more than Collapser::kWideFan faces): each fan
// centre's flatness and its kept collapse costs equal, after every collapse, what a walk of its
// star and a fresh cost give (Collapser::check_kept_state).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "decimate/collapser.hpp"
#include "collapse_setup.hpp"
#include "core/portable.hpp"
#include "meshes.hpp"

using topstoc::Collapser;

namespace {

// A closed fan lens inside [-1, 1]: a rim of k vertices (radii jittered) in the plane z = 0,
// a flat fan above it from the centre (0, 0, 0) and a cone below from (0, 0, -0.6).
topstoc_test::Arrays fan_lens(int32_t k, std::mt19937& random) {
  std::uniform_real_distribution<double> jitter(0.85, 1.0);
  topstoc_test::Arrays mesh;
  for (int32_t i = 0; i < k; ++i) {
    const double a = 2.0 * topstoc::kPi * i / k, r = 0.9 * jitter(random);
    mesh.positions.insert(mesh.positions.end(), {r * std::cos(a), r * std::sin(a), 0.0});
  }
  mesh.positions.insert(mesh.positions.end(), {0.0, 0.0, 0.0, 0.0, 0.0, -0.6});
  const int32_t top = k, bottom = k + 1;
  for (int32_t i = 0; i < k; ++i) {
    const int32_t next = (i + 1) % k;
    mesh.triangles.insert(mesh.triangles.end(), {top, i, next, bottom, next, i});
  }
  return mesh;
}

int64_t collapse_checking(Collapser& collapser, int32_t keep) {
  int64_t checked = 0;
  while (collapser.live_vertices() > keep && collapser.collapse_one() >= 0) {
    const int64_t step = collapser.check_kept_state();
    REQUIRE(step >= 0);
    checked += step;
  }
  return checked;
}

}  // namespace

TEST_CASE("a fan centre's kept flatness and costs equal a fresh walk after every collapse") {
  std::mt19937 random(3);
  for (const int32_t k : {200, 333}) {
    const auto mesh = fan_lens(k, random);
    const int32_t n = k + 2;
    std::vector<int32_t> triangles = mesh.triangles, corners(triangles.size());
    for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
    auto setup = topstoc_test::torus_setup(mesh);
    setup.input_floor2.assign(n, 1e-6);  // thin input triangles: the checks ask for flatness
    Collapser collapser(triangles, corners, std::move(setup));
    REQUIRE(collapser.check_kept_state() > 0);
    const int64_t checked = collapse_checking(collapser, n / 3);
    CHECK(checked > 0);
    // The sliver clean-up thins the fans a round at a time, then the rest goes one by one.
    collapser.remove_thin(0.3, {n / 6, 0}, {true, false});
    REQUIRE(collapser.check_kept_state() >= 0);
    collapse_checking(collapser, 8);
    CHECK(collapser.live_vertices() <= n / 3);
  }
}
