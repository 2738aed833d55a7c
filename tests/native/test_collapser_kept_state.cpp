// The collapser's kept state at wide vertices (more than Collapser::kWideFan faces): each fan
// centre's flatness and its kept collapse costs equal, after every collapse, what a walk of its
// star and a fresh cost give (Collapser::check_kept_state).
#include <doctest/doctest.h>

#include <cmath>
#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <random>
#include <vector>

#include "decimate/collapser.hpp"
#include "topstoc/core/parallel.hpp"
#include "collapse_setup.hpp"
#include "meshes.hpp"

using topstoc::Collapser;

namespace {

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
    const auto mesh = topstoc_test::fan_lens(k, random);
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

namespace {

// The live triangles after a run to `keep` vertices of the fan lens of k rim vertices, on `threads`
// threads, and the batches it took.
std::vector<int32_t> run_lens(int32_t k, int32_t keep, int threads, int64_t& batches, std::vector<double>& at) {
  std::mt19937 random(5);
  const auto mesh = topstoc_test::fan_lens(k, random);
  std::vector<int32_t> triangles = mesh.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  const int saved = topstoc::max_threads();
  topstoc::set_max_threads(threads);
  auto setup = topstoc_test::torus_setup(mesh);
  setup.input_floor2.assign(k + 2, 1e-6);  // the fans' slivers may stay as thin where flat
  setup.locked[k] = setup.locked[k + 1] = 1;  // the centres stay: the rim collapses along itself
  Collapser collapser(triangles, corners, std::move(setup));
  collapser.run({keep, 0});
  topstoc::set_max_threads(saved);
  batches = collapser.batches();
  at.clear();
  for (int32_t v = 0; v < k + 2; ++v) at.insert(at.end(), collapser.world(v), collapser.world(v) + 3);
  std::vector<int32_t> live;
  for (int32_t t = 0; t < int32_t(triangles.size() / 3); ++t)
    if (collapser.face_alive(t)) live.insert(live.end(), &triangles[3 * size_t(t)], &triangles[3 * size_t(t) + 3]);
  return live;
}

}  // namespace

TEST_CASE("collapses beside a fan's centre share a batch, and the lens stays a closed lens") {
  // Every rim collapse has both centres in its ring. Reserved like an end, a centre let one rim
  // collapse into a batch (24,387 batches for these 18,002 collapses); beside it, they share
  // (9,333: about half of a batch's picks are the mirror of another, or stale).
  const int32_t k = 20000, keep = 2000;
  int64_t batches = 0, batches_one_thread = 0;
  std::vector<double> at, at_one_thread;
  const std::vector<int32_t> live = run_lens(k, keep, 2, batches, at);
  CHECK(batches < (k + 2 - keep) * 2 / 3);
  // The same result on one thread (the batches do not depend on the threads).
  CHECK(run_lens(k, keep, 1, batches_one_thread, at_one_thread) == live);
  CHECK(at_one_thread == at);
  CHECK(batches_one_thread == batches);
  // A closed lens: every edge in two triangles, V - E + F = 2, each fan's triangles facing its way.
  std::map<std::pair<int32_t, int32_t>, int> edges;
  std::set<int32_t> vertices;
  int32_t up = 0, down = 0;  // triangles of the flat fan facing +z, of the cone facing -z
  for (size_t t = 0; t < live.size(); t += 3) {
    for (int j = 0; j < 3; ++j) {
      const int32_t a = live[t + j], b = live[t + (j + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
      vertices.insert(a);
    }
    const double *a = &at[3 * size_t(live[t])], *b = &at[3 * size_t(live[t + 1])], *c = &at[3 * size_t(live[t + 2])];
    const double z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    const bool top = std::find(&live[t], &live[t] + 3, k) != &live[t] + 3;
    const bool bottom = std::find(&live[t], &live[t] + 3, k + 1) != &live[t] + 3;
    up += top && !bottom && z > 0.0;
    down += bottom && !top && z < 0.0;
  }
  for (const auto& [edge, count] : edges) REQUIRE(count == 2);
  CHECK(int64_t(vertices.size()) - int64_t(edges.size()) + int64_t(live.size() / 3) == 2);
  CHECK(up + down == int32_t(live.size() / 3));
  CHECK(up == down);
}
