// The max's bracket (bounded_max.hpp) counts its budget in triangles measured as well as in
// lookups: on a flat fan every sliver's box holds the centre and a lookup there measures most of
// them, so a budget of lookups alone let one bracket measure hundreds of times more triangles
// than on an ordinary mesh (the tiny budgets' fit took a minute on a fan of 1,500 slivers).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/portable.hpp"
#include "distance/bounded_max.hpp"
#include "topstoc/distance/bvh.hpp"

using topstoc::MaxBracket;
using topstoc::Surface;

namespace {

// A disc of radius 1 fanned from its centre: n rim vertices, then the centre.
Surface fan(int32_t n) {
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  for (int32_t i = 0; i < n; ++i) {
    const double a = 2.0 * topstoc::kPi * i / n;
    positions.insert(positions.end(), {std::cos(a), std::sin(a), 0.0});
    triangles.insert(triangles.end(), {i, (i + 1) % n, n});
  }
  positions.insert(positions.end(), {0.0, 0.0, 0.0});
  return Surface(std::move(positions), std::move(triangles));
}

// The exact max from the fan's points to `to`: the distance to a triangle is convex, so over each
// of the fan's triangles it peaks at a corner.
double brute_force_max(const Surface& from, const Surface& to) {
  double worst = 0.0, q[3];
  const auto& p = to.positions();
  const auto& t = to.triangles();
  for (size_t v = 0; v < from.positions().size(); v += 3) {
    double nearest = INFINITY;
    for (size_t f = 0; f < t.size(); f += 3)
      nearest = std::min(nearest, topstoc::closest_point_on_triangle(&from.positions()[v], &p[3 * size_t(t[f])],
                                                                     &p[3 * size_t(t[f + 1])], &p[3 * size_t(t[f + 2])], q));
    worst = std::max(worst, nearest);
  }
  return std::sqrt(worst);
}

}  // namespace

TEST_CASE("a bracket over a flat fan stops at its budget of measured triangles, and stays valid") {
  const Surface fine = fan(1500), coarse = fan(150);
  const double exact = brute_force_max(fine, coarse);
  CHECK(exact == doctest::Approx(1.0 - std::cos(topstoc::kPi / 150)).epsilon(1e-3));  // the chords' sagitta
  for (const bool tree : {false, true}) {
    CAPTURE(tree);
    const int64_t budget = 4000;
    const MaxBracket b = tree ? topstoc::bound_max_distance_by_tree(coarse, fine, 1e-2, budget)
                              : topstoc::bound_max_distance_by_tree(fine, coarse, 1e-2, budget);
    // each lookup measures far more triangles than the budget allows a lookup on average
    CHECK(b.queries < budget / 2);
    const double truth = tree ? 0.0 : exact;  // the coarse polygon lies inside the fine one
    CHECK(b.lower <= truth * (1 + 1e-9) + 1e-12);
    CHECK(b.upper >= truth * (1 - 1e-9));
  }
}
