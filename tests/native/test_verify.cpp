// The final output check (verify.hpp) at pinched vertices: hand-made outputs of small pinched
// inputs, each wrong in one way at the pinch, must fail; the input itself must pass. Several
// of them keep every count the rest of the check compares (Euler characteristic, boundary
// loops, components), so only the per-fan comparison can see them.
#include <doctest/doctest.h>

#include <vector>

#include "meshes.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/decimate/verify.hpp"

using namespace topstoc;

namespace {

// Wings: open fans around vertex 0 (a bowtie for two). Wing w has the rim vertices
// 1 + w * (size + 1) ... and `size` triangles (0, r, r + 1), all oriented alike.
topstoc_test::Arrays wings(int32_t count, int32_t size) {
  topstoc_test::Arrays a;
  a.positions = {0, 0, 0};
  const double pi = std::acos(-1.0);
  for (int32_t w = 0; w < count; ++w) {
    const int32_t first = 1 + w * (size + 1);
    for (int32_t r = 0; r <= size; ++r) {
      const double angle = 2 * pi * (w + 0.8 * r / size) / count;
      a.positions.insert(a.positions.end(), {std::cos(angle), std::sin(angle), 0.1 * w});
    }
    for (int32_t r = 0; r < size; ++r) a.triangles.insert(a.triangles.end(), {0, first + r, first + r + 1});
  }
  return a;
}

// Checks an output made of the input's own vertices: `caller_kept` (caller ids) become
// output vertices 0, 1, ... and `caller_triangles` use caller ids too.
OutputCheck check(const topstoc_test::Arrays& input, const std::vector<int32_t>& caller_kept,
                  const std::vector<int32_t>& caller_triangles) {
  const Mesh mesh(input.positions, input.triangles.data(), input.num_triangles());
  const auto layout = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
  std::vector<int32_t> kept, output_of(input.positions.size() / 3, -1), triangles;
  std::vector<double> positions;
  for (int32_t v : caller_kept) {
    output_of[v] = static_cast<int32_t>(kept.size());
    kept.push_back(mesh.vertex_index()[v]);
    positions.insert(positions.end(), input.positions.begin() + 3 * v, input.positions.begin() + 3 * v + 3);
  }
  for (int32_t v : caller_triangles) triangles.push_back(output_of[v]);
  return check_output(mesh, *layout, kept, positions, triangles);
}

std::vector<int32_t> all_vertices(const topstoc_test::Arrays& a) {
  std::vector<int32_t> out(a.positions.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) out[i] = int32_t(i);
  return out;
}

}  // namespace

TEST_CASE("pinched input returned unchanged: passes") {
  for (int32_t count : {2, 3, 5}) {
    const auto input = wings(count, 3);
    const OutputCheck c = check(input, all_vertices(input), input.triangles);
    CHECK(c.pinched_fans_changed == 0);
    CHECK(c.violations() == 0);
  }
}

TEST_CASE("bowtie with a wing lost: only the per-fan comparison fails") {
  // Wings {0,1,2,3} and {0,4,5,6}: without the second, chi (1), boundary groups (1: the two
  // rims touch at the pinch) and components (1) all stay the same.
  const auto input = wings(2, 2);
  const OutputCheck c = check(input, {0, 1, 2, 3}, {0, 1, 2, 0, 2, 3});
  CHECK(c.pinched_fans_changed == 1);
  CHECK(c.violations() == 1);
  CHECK(c.euler_changed == 0);
  CHECK(c.boundary_loops_changed == 0);
  CHECK(c.lost_components == 0);
  CHECK(c.describe() == "1 pinched vertices whose fans changed");
}

TEST_CASE("bowtie with its wings joined into one fan: fails") {
  const auto input = wings(2, 2);
  // a triangle (0, 3, 4) closes the gap between the wings: one open fan around 0
  const OutputCheck c = check(input, all_vertices(input), {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5, 0, 5, 6});
  CHECK(c.pinched_fans_changed == 1);
}

TEST_CASE("a wing closed around the pinch: fails") {
  const auto input = wings(2, 3);  // wing 0: 0-1-2-3-4, wing 1: 0-5-6-7-8
  // wing 0 rebuilt as a closed fan (0,1,2) (0,2,3) (0,3,1) without vertex 4
  const OutputCheck c = check(input, {0, 1, 2, 3, 5, 6, 7, 8}, {0, 1, 2, 0, 2, 3, 0, 3, 1, 0, 5, 6, 0, 6, 7, 0, 7, 8});
  CHECK(c.pinched_fans_changed == 1);
}

TEST_CASE("three wings, counts and kinds kept, but on the wrong sheets: fails") {
  // Wings 0-1-2-3-4, 0-5-6-7-8, 0-9-10-11-12. The output keeps three open fans at 0, but two
  // of them are pieces of the second wing (its middle triangle removed) and the third wing is
  // gone: only the sheets tell.
  const auto input = wings(3, 3);
  const OutputCheck c =
      check(input, {0, 1, 2, 3, 4, 5, 6, 7, 8}, {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 5, 6, 0, 7, 8});
  CHECK(c.pinched_fans_changed == 1);
}

TEST_CASE("the pinched vertex dropped: fails") {
  const auto input = wings(2, 2);
  const OutputCheck c = check(input, {1, 2, 3, 4, 5, 6}, {1, 2, 3, 4, 5, 6});
  CHECK(c.pinched_fans_changed == 1);
}

TEST_CASE("a triangle across two wings away from the pinch: fails") {
  const auto input = wings(2, 3);
  // the output's wing pieces joined by (3, 6, 5): one sheet over two input sheets
  const OutputCheck c = check(input, all_vertices(input),
                              {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 5, 6, 0, 6, 7, 0, 7, 8, 3, 6, 5});
  CHECK(c.pinched_fans_changed >= 1);
}

TEST_CASE("manifold inputs: the per-fan comparison stays silent") {
  for (const auto& input : {topstoc_test::torus(6, 4), topstoc_test::octahedron(), topstoc_test::grid(3, 2)}) {
    const OutputCheck c = check(input, all_vertices(input), input.triangles);
    CHECK(c.pinched_fans_changed == 0);
    CHECK(c.violations() == 0);
  }
}
