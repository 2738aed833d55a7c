// self_intersections with only_with: the pairs that have a flagged triangle, and the flagged
// zero-area triangles, exactly as filtering the full answer gives them.
#include <doctest/doctest.h>

#include <random>
#include <utility>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/self_intersections.hpp"

using namespace topstoc;

TEST_CASE("self_intersections only_with: the full answer's pairs that have a flagged triangle") {
  // A flat grid and the same grid stood upright through it, plus a zero-area triangle: many
  // crossing pairs, coplanar neighbours, and a (t, t) entry.
  topstoc_test::Arrays a = topstoc_test::grid(8, 8);
  const int32_t n = int32_t(a.positions.size() / 3);
  const topstoc_test::Arrays upright = topstoc_test::grid(8, 8);
  for (size_t v = 0; v < upright.positions.size(); v += 3)
    a.positions.insert(a.positions.end(), {upright.positions[v], 0.37, upright.positions[v + 1] - 0.5});
  for (int32_t c : upright.triangles) a.triangles.push_back(c + n);
  a.triangles.insert(a.triangles.end(), {0, 1, 2});  // grid vertices 0, 1, 2 lie on a line
  const int32_t m = int32_t(a.num_triangles()), vertices = int32_t(a.positions.size() / 3);
  const auto all = self_intersections(a.positions.data(), vertices, a.triangles.data(), m);
  REQUIRE(all.size() > 20);
  REQUIRE(all.back() == std::make_pair(m - 1, m - 1));
  std::mt19937 random(5);
  for (int round = 0; round < 20; ++round) {
    std::vector<uint8_t> flag(m);
    for (auto& f : flag) f = random() % 7 == 0;
    if (round == 0) flag.assign(m, 1);
    if (round == 1) flag[m - 1] = 1;
    std::vector<std::pair<int32_t, int32_t>> expected;
    for (const auto& pair : all)
      if (flag[pair.first] || flag[pair.second]) expected.push_back(pair);
    CHECK(self_intersections(a.positions.data(), vertices, a.triangles.data(), m, 0, flag.data()) == expected);
  }
}
