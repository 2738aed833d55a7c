// How run()'s batches take their collapses where the cheapest ones crowd one place: tied costs
// on a flat strip (ties go by vertex id, so the first ones in the queue are neighbours), and
// collapses with a fan's centre at one end (their ring is the whole fan).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "decimate/collapse_snapshots.hpp"
#include "decimate/collapser.hpp"
#include "topstoc/core/parallel.hpp"
#include "collapse_setup.hpp"
#include "meshes.hpp"

using topstoc::Collapser;

namespace {

struct Run {
  std::vector<int32_t> live;  // the live triangles' corners
  int64_t collapses = 0, taken = 0, ring_faces = 0, batches = 0;
};

Run run_to(const topstoc_test::Arrays& mesh, topstoc::CollapseSetup setup, int32_t keep, int threads) {
  std::vector<int32_t> triangles = mesh.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  const int saved = topstoc::max_threads();
  topstoc::set_max_threads(threads);
  Collapser collapser(triangles, corners, std::move(setup));
  Run run;
  run.collapses = collapser.run({keep, 0});
  topstoc::set_max_threads(saved);
  run.taken = collapser.taken(), run.ring_faces = collapser.ring_faces(), run.batches = collapser.batches();
  for (int32_t t = 0; t < int32_t(triangles.size() / 3); ++t)
    if (collapser.face_alive(t)) run.live.insert(run.live.end(), &triangles[3 * size_t(t)], &triangles[3 * size_t(t) + 3]);
  return run;
}

// A flat strip of 8 x `rows` cells, each 1 long and 0.001 wide: every triangle a needle, every
// collapse cost 0. Vertex (i, j) = i * (rows + 1) + j, so neighbours along a column have
// consecutive ids. The border is locked.
topstoc_test::Arrays needle_strip(int32_t rows, topstoc::CollapseSetup& setup) {
  topstoc_test::Arrays mesh = topstoc_test::grid(8, rows);
  for (size_t v = 0; v < mesh.positions.size() / 3; ++v) mesh.positions[3 * v + 1] *= 0.001;
  setup = topstoc_test::torus_setup(mesh);
  for (int32_t i = 0; i <= 8; ++i)
    for (int32_t j = 0; j <= rows; ++j)
      if (i == 0 || i == 8 || j == 0 || j == rows) setup.locked[i * (rows + 1) + j] = 1;
  setup.input_floor2.assign(setup.locked.size(), 2.9e-6);  // needles as thin as the input's may stay
  return mesh;
}

// Triangles of `live` (corners into `positions`) facing -z.
int64_t facing_down(const std::vector<int32_t>& live, const std::vector<double>& positions) {
  int64_t down = 0;
  for (size_t t = 0; t < live.size(); t += 3) {
    const double *a = &positions[3 * size_t(live[t])], *b = &positions[3 * size_t(live[t + 1])],
                 *c = &positions[3 * size_t(live[t + 2])];
    down += (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0;
  }
  return down;
}

}  // namespace

TEST_CASE("tied collapses on a flat strip of needles do not each take a full batch") {
  // With batches of 128 the first reservation's ring held the 127 after it (its neighbours by
  // id), queued again each batch: hundreds taken from the queue per collapse.
  const int32_t rows = 3000;
  topstoc::CollapseSetup setup;
  const topstoc_test::Arrays mesh = needle_strip(rows, setup);
  const int32_t n = int32_t(setup.locked.size()), keep = n / 4;
  const Run run = run_to(mesh, setup, keep, 2);
  REQUIRE(run.collapses > n / 2);
  CHECK(run.taken < 20 * run.collapses);
  // Still a flat strip: every triangle faces up; the same collapses on one thread.
  CHECK(facing_down(run.live, mesh.positions) == 0);
  CHECK(run_to(mesh, setup, keep, 1).live == run.live);
}

TEST_CASE("a collapse at a fan's centre is checked before the fan is walked for its batch") {
  // Rim vertices queued for the centre are refused (the fan would fold), but their reservation
  // walked the whole fan twice first: about k faces a batch.
  std::mt19937 random(5);
  const int32_t k = 20000, keep = 2000;
  const topstoc_test::Arrays mesh = topstoc_test::fan_lens(k, random);
  auto setup = topstoc_test::torus_setup(mesh);
  setup.input_floor2.assign(k + 2, 1e-6);  // the fans' slivers may stay as thin where flat
  const Run run = run_to(mesh, setup, keep, 2);
  REQUIRE(run.collapses == k + 2 - keep);
  CHECK(run.ring_faces < 64 * run.batches);
  CHECK(run_to(mesh, setup, keep, 1).live == run.live);
}

TEST_CASE("a state kept where a capped run's tail starts resumes to the fresh run") {
  // The cap is part of the collapser's state: a run resumed from a kept state (the Live
  // Preview's, an error search's) takes the batches the uninterrupted run takes.
  for (const int32_t rows : {1000, 2000, 3000, 5000}) {
    topstoc::CollapseSetup setup;
    const topstoc_test::Arrays mesh = needle_strip(rows, setup);
    const int32_t n = int32_t(setup.locked.size());
    for (const int32_t first_target : {n / 2, 2 * n / 3}) {
      std::vector<int32_t> triangles = mesh.triangles, corners(triangles.size());
      for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
      const std::vector<int32_t> sources = corners;
      Collapser first(triangles, corners, setup);
      std::shared_ptr<const topstoc::CollapseSnapshots::Entry> kept;
      first.run({first_target, 0}, [&](const Collapser& state, int32_t made) {
        kept = topstoc::snapshot({}, first_target, made, state);
      });
      REQUIRE(bool(kept));
      std::vector<int32_t> resumed_triangles, resumed_sources;
      auto resumed = topstoc::resumed(*kept, resumed_triangles, resumed_sources, {0});
      const int32_t resumed_collapses = kept->collapses + resumed->run({n / 4, 0});
      std::vector<int32_t> fresh_triangles = mesh.triangles, fresh_sources = sources;
      Collapser fresh(fresh_triangles, fresh_sources, setup);
      CHECK(fresh.run({n / 4, 0}) == resumed_collapses);
      CHECK(resumed_triangles == fresh_triangles);
      CHECK(resumed_sources == fresh_sources);
    }
  }
}
