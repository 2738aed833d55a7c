// Cancelling an engine call from another thread (progress.hpp CancelScope): the collapses stop at
// their next batch with Cancelled, and a scope gives the thread back the flag it had before.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "collapse_setup.hpp"
#include "decimate/collapser.hpp"
#include "meshes.hpp"
#include "topstoc/core/progress.hpp"

using topstoc::CancelFlag;
using topstoc::CancelScope;
using topstoc::Cancelled;
using topstoc::Collapser;

namespace {

int32_t alive(const Collapser& c) {
  int32_t count = 0;
  for (int32_t v = 0; v < c.vertices(); ++v) count += c.vertex_alive(v);
  return count;
}

}  // namespace

TEST_CASE("collapses under a set cancel flag stop with Cancelled before their next batch") {
  const auto mesh = topstoc_test::torus(40, 20, 0.6, 0.25);
  const int32_t n = int32_t(mesh.positions.size() / 3);
  std::vector<int32_t> triangles = mesh.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  Collapser collapser(triangles, corners, topstoc_test::torus_setup(mesh));
  CancelFlag flag{false};
  CancelScope scope(&flag);
  collapser.run({n / 2, 0});  // not set: runs to its target
  CHECK(alive(collapser) == n / 2);
  flag = true;
  CHECK_THROWS_AS(collapser.run({n / 8, 0}), Cancelled);
  CHECK(alive(collapser) == n / 2);
}

TEST_CASE("a cancel scope is the calling thread's only, and restores the flag it replaced") {
  CancelFlag outer{true}, inner{false};
  CHECK_NOTHROW(topstoc::check_cancelled("none"));
  {
    CancelScope a(&outer);
    CHECK_THROWS_AS(topstoc::check_cancelled("outer"), Cancelled);
    {
      CancelScope b(&inner);
      CHECK_NOTHROW(topstoc::check_cancelled("inner"));
    }
    CHECK_THROWS_AS(topstoc::check_cancelled("outer again"), Cancelled);
  }
  CHECK_NOTHROW(topstoc::check_cancelled("none again"));
}
