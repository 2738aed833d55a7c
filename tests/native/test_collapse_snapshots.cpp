// Kept collapse states (collapse_snapshots.hpp): a run resumed from the state an earlier run kept
// where its batches started to depend on its target gives the fresh run's triangles, also on a
// team of another size than the one the state was kept on. The input surfaces kept with them:
// one per mesh and step, made once, the least recently used dropped beyond two.
#include <doctest/doctest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "decimate/collapse_snapshots.hpp"
#include "decimate/collapser.hpp"
#include "decimate/deviation.hpp"
#include "collapse_setup.hpp"
#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/core/parallel.hpp"

using topstoc::Collapser;

TEST_CASE("a kept collapse state resumed toward a lower target gives the fresh run, on any team size") {
  const auto mesh = topstoc_test::torus(100, 50, 0.6, 0.25);  // 5,000 vertices: batches of up to 4
  const int32_t n = int32_t(mesh.positions.size() / 3);
  std::vector<int32_t> corners(mesh.triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  const int saved = topstoc::max_threads();
  for (const int kept_on : {1, 2}) {
    topstoc::set_max_threads(kept_on);
    std::vector<int32_t> triangles = mesh.triangles, sources = corners;
    Collapser first(triangles, sources, topstoc_test::torus_setup(mesh));
    std::shared_ptr<const topstoc::CollapseSnapshots::Entry> kept;
    int32_t reports = 0;
    first.run({n / 4, 0}, [&](const Collapser& state, int32_t made) {
      kept = topstoc::snapshot({}, n / 4, made, state);
      ++reports;
    });
    REQUIRE(reports == 1);
    CHECK(kept->collapses > n / 2);  // most of the way: the tail is near the target

    topstoc::set_max_threads(3 - kept_on);
    std::vector<int32_t> resumed_triangles, resumed_sources;
    auto resumed = topstoc::resumed(*kept, resumed_triangles, resumed_sources, {0});
    const int32_t resumed_collapses = kept->collapses + resumed->run({n / 10, 0});
    std::vector<int32_t> fresh_triangles = mesh.triangles, fresh_sources = corners;
    Collapser fresh(fresh_triangles, fresh_sources, topstoc_test::torus_setup(mesh));
    const int32_t fresh_collapses = fresh.run({n / 10, 0});
    CHECK(resumed_collapses == fresh_collapses);
    CHECK(resumed_triangles == fresh_triangles);
    CHECK(resumed_sources == fresh_sources);
    int32_t same = 0;
    for (int32_t t = 0; t < int32_t(fresh_triangles.size() / 3); ++t)
      same += resumed->face_alive(t) == fresh.face_alive(t);
    CHECK(same == int32_t(fresh_triangles.size() / 3));
  }
  topstoc::set_max_threads(saved);
}

TEST_CASE("input surfaces are kept per mesh and step, made once, the least recently used dropped beyond two") {
  const auto arrays = topstoc_test::torus(40, 20, 0.6, 0.25);
  const int64_t m = int64_t(arrays.triangles.size() / 3);
  const topstoc::Mesh mesh(arrays.positions, arrays.triangles.data(), m), same_arrays(arrays.positions, arrays.triangles.data(), m);
  std::vector<int32_t> triangles = arrays.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  const Collapser collapser(triangles, corners, topstoc_test::torus_setup(arrays));
  topstoc::CollapseSnapshots kept;
  int made = 0;
  auto get = [&](const topstoc::Mesh& of, int64_t step) {
    return kept.input_surface(topstoc::input_surface_key(of, collapser, step), [&] {
      ++made;
      return topstoc::normalised_input(of, collapser, step);
    });
  };
  const auto whole = get(mesh, 1);
  REQUIRE(whole->num_triangles() == mesh.num_faces());
  for (int32_t w = 0; w < mesh.num_vertices(); ++w) {
    double expected[3];
    collapser.normalise(mesh.position(w), expected);
    for (int i = 0; i < 3; ++i) CHECK(whole->positions()[3 * size_t(w) + i] == expected[i]);
  }
  CHECK(get(mesh, 1).get() == whole.get());
  CHECK(made == 1);
  const auto every_third = get(mesh, 3);
  CHECK(every_third->num_triangles() == (mesh.num_faces() + 2) / 3);
  for (int32_t t = 0; t < every_third->num_triangles(); ++t)
    for (int j = 0; j < 3; ++j) CHECK(every_third->triangles()[3 * size_t(t) + j] == mesh.faces()[9 * size_t(t) + j]);
  CHECK(made == 2);
  CHECK(get(mesh, 1).get() == whole.get());  // now the most recently used
  // Another mesh (the same arrays prepared again): its own surface; the step-3 one goes.
  CHECK(get(same_arrays, 1).get() != whole.get());
  CHECK(made == 3);
  CHECK(kept.surfaces() == 2);
  CHECK(get(mesh, 1).get() == whole.get());
  CHECK(made == 3);
  get(mesh, 3);
  CHECK(made == 4);
  kept.clear();
  CHECK(kept.surfaces() == 0);
  CHECK(get(mesh, 1).get() != whole.get());
  CHECK(made == 5);
}
