// The draw without guidance against its definition (sampling.hpp): the vertices with p = 1, the
// sharpest curve bends (up to an eighth of the target) and three vertices of each short boundary
// loop, and of the others the target's remainder with the smallest Pareto keys (U/(1-U)) ((1-p)/p), U the
// vertex's uniform for the seed. A slider's draws with one seed take a faster way after the
// first (a candidate order kept on the layout); both ways must give the definition's samples.
#include <doctest/doctest.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <numeric>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/random.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/decimate/decimate.hpp"
#include "topstoc/decimate/flood_cache.hpp"
#include "topstoc/decimate/sampling.hpp"
#include "topstoc/io/io.hpp"

using namespace topstoc;

namespace {

// The definition, by sorting every vertex's key.
std::vector<int32_t> defined_draw(const Mesh& mesh, const FeatureLayout& layout, const SamplingParams& params,
                                  int32_t target, double rate) {
  const auto p = sampling_probabilities(mesh, layout, params, rate);
  // The sharpest curve bends, up to an eighth of the target, are kept like p = 1.
  std::vector<uint8_t> bend(mesh.num_vertices(), 0);
  for (int32_t i = 0; i < int32_t(layout.curve_bends.size()) && i < target / 8; ++i) bend[layout.curve_bends[i]] = 1;
  std::vector<uint8_t> kept(mesh.num_vertices(), 0);
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) kept[v] = p[v] >= 1.0 || (bend[v] && p[v] > 0.0);
  // Each boundary loop too short to expect three samples (length x target / vertices under 3)
  // and holding fewer than three kept vertices keeps those at 0, 1/3 and 2/3 of its sorted
  // vertices (p > 0, not kept) until it holds three, where they add up to an eighth of the target.
  const double per_vertex = double(target) / double(mesh.num_vertices() - mesh.report().isolated_vertices);
  std::vector<uint8_t> loop_kept(mesh.num_vertices(), 0);
  int64_t added = 0;
  for (size_t loop = 0; loop + 1 < layout.boundary_loop_offsets.size(); ++loop) {
    const int32_t b = layout.boundary_loop_offsets[loop], n = layout.boundary_loop_offsets[loop + 1] - b;
    if (n < 3 || double(n) * per_vertex >= 3.0) continue;
    int32_t have = 0;
    for (int32_t i = 0; i < n; ++i) have += kept[layout.boundary_loop_vertices[size_t(b + i)]];
    for (int32_t k = 0; k < 3 && have < 3; ++k) {
      const int32_t v = layout.boundary_loop_vertices[size_t(b + k * n / 3)];
      if (p[v] > 0.0 && !kept[v]) added += !loop_kept[v], loop_kept[v] = 1, ++have;
    }
  }
  if (4 * added < target) std::fill(loop_kept.begin(), loop_kept.end(), 0);
  std::vector<int32_t> drawn;
  std::vector<std::pair<double, int32_t>> keys;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    if (kept[v] || loop_kept[v]) {
      drawn.push_back(v);
    } else if (p[v] > 0.0) {
      const double u = uniform01(params.seed, 1, uint64_t(mesh.vertex_source()[v]));
      keys.push_back({(u / (1.0 - u)) * ((1.0 - p[v]) / p[v]), v});
    }
  }
  std::sort(keys.begin(), keys.end());
  const size_t take = std::min(keys.size(), size_t(std::max<int64_t>(0, int64_t(target) - int64_t(drawn.size()))));
  for (size_t i = 0; i < take; ++i) drawn.push_back(keys[i].second);
  std::sort(drawn.begin(), drawn.end());
  return drawn;
}

// Targets from most vertices down to fewer than the corners, and back up; two seeds. Each draw is
// made on a fresh layout (a first draw: every vertex tested) and on one layout kept across the
// draws of a seed (a slider: the kept order after the first), and both must be the definition.
void check_draws(const Mesh& mesh, const std::function<std::shared_ptr<const FeatureLayout>()>& make_layout) {
  const auto layout = make_layout();
  const int32_t n = mesh.num_vertices();
  int32_t corners = 0;
  for (int32_t v = 0; v < n; ++v) corners += layout->is_corner(v);
  std::vector<int32_t> targets;
  for (double f : {0.6, 0.3, 0.2, 0.1, 0.05, 0.02, 0.01, 0.003}) targets.push_back(std::max(1, int32_t(f * n)));
  targets.push_back(corners + 3);
  targets.push_back(corners / 2);
  for (double f : {0.004, 0.04, 0.4, 0.97}) targets.push_back(int32_t(f * n));
  for (uint64_t seed : {1, 2}) {
    SamplingParams params;
    params.seed = seed;
    const auto slider = make_layout();
    int32_t ordered = 0;
    for (int32_t target : targets) {
      CAPTURE(seed);
      CAPTURE(target);
      const SampleSet first = select_samples(mesh, *make_layout(), params, target);
      const SampleSet later = select_samples(mesh, *slider, params, target);
      const auto defined = defined_draw(mesh, *layout, params, target, first.rate);
      CHECK(first.samples == defined);
      CHECK(later.samples == defined);
      CHECK(later.forced == first.forced);
      CHECK(later.expected == first.expected);  // to the bit, whichever way
      const auto p = sampling_probabilities(mesh, *layout, params, first.rate);
      CHECK(first.expected == doctest::Approx(std::accumulate(p.begin(), p.end(), 0.0)).epsilon(1e-9));
      ordered += slider->candidate_order.get() != nullptr;
    }
    CHECK(ordered == int32_t(targets.size()) - 1);  // every draw after the first had the order
  }
}

}  // namespace

TEST_CASE("draws without guidance take the smallest Pareto keys, the first draw of a seed and the later ones") {
  SUBCASE("a mesh with holes (tests/data): boundary curves, p = sqrt(k q)") {
    const MeshFile file = read_mesh_path(TOPSTOC_TEST_DATA "/open_boundary/cgal_elephant-with-holes.off");
    const Mesh mesh(file.vertices, file.triangles.data(), file.num_triangles());
    auto make_layout = [&]() { return build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0); };
    const auto layout = make_layout();
    REQUIRE(std::count(layout->vertex_feature.begin(), layout->vertex_feature.end(), 1) > 100);
    check_draws(mesh, make_layout);
  }
  SUBCASE("a sheet with a hole in one cell in nine: three vertices of each short loop") {
    const auto grid = topstoc_test::grid(60, 60);
    std::vector<int32_t> triangles;
    for (int32_t i = 0; i < 60; ++i)
      for (int32_t j = 0; j < 60; ++j)
        if (i % 3 != 1 || j % 3 != 1)
          triangles.insert(triangles.end(), &grid.triangles[6 * size_t(i * 60 + j)], &grid.triangles[6 * size_t(i * 60 + j) + 6]);
    const Mesh mesh(grid.positions, triangles.data(), int64_t(triangles.size() / 3));
    auto make_layout = [&]() { return build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0); };
    const auto layout = make_layout();
    REQUIRE(layout->boundary_loop_offsets.size() == 400 + 2);  // 400 holes and the rim
    SamplingParams params;
    CHECK(select_samples(mesh, *layout, params, 1000).forced >= 3 * 400);  // the holes' three each
    CHECK(select_samples(mesh, *layout, params, 1000).forced < 3 * 400 + 400);
    check_draws(mesh, make_layout);
  }
  SUBCASE("a grid with a row and a column as borders: corners, p = 1") {
    const auto arrays = topstoc_test::grid(60, 50);
    const Mesh mesh(arrays.positions, arrays.triangles.data(), arrays.num_triangles());
    std::vector<int32_t> border;
    for (int32_t j = 0; j < 50; ++j) border.insert(border.end(), {20 * 51 + j, 20 * 51 + j + 1});  // column 20
    for (int32_t i = 0; i < 60; ++i) border.insert(border.end(), {i * 51 + 30, (i + 1) * 51 + 30});  // row 30
    auto make_layout = [&]() {
      return build_feature_layout(mesh, nullptr, 0, border.data(), int64_t(border.size() / 2), 0.0);
    };
    const auto layout = make_layout();
    REQUIRE(std::count(layout->vertex_corner.begin(), layout->vertex_corner.end(), 1) >= 5);
    check_draws(mesh, make_layout);
  }
}

// The engine's door: decimate() checks the sampling parameters for every caller (the Python job
// checks them first, with the parameter's name; a C++ caller has only this).
TEST_CASE("decimate refuses sampling parameters out of range") {
  const auto arrays = topstoc_test::torus(12, 8);
  const Mesh mesh(arrays.positions, arrays.triangles.data(), arrays.num_triangles());
  const auto layout = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
  DecimateParams params;
  params.target_vertices = 20;
  CHECK(decimate(mesh, *layout, params).kept.size() > 0);
  std::vector<double> guidance(mesh.num_vertices(), 0.0);
  guidance[5] = 1.5;
  params.sampling.guidance = guidance.data();
  CHECK_THROWS_WITH_AS(decimate(mesh, *layout, params), "guidance of vertex 5 is 1.500000; it must lie in [-1, 1]",
                       std::invalid_argument);
  params.sampling.guidance = nullptr;
  params.sampling.adaptivity = 1.5;
  CHECK_THROWS_AS(decimate(mesh, *layout, params), std::invalid_argument);
  params.sampling.adaptivity = 0.5;
  params.refine = 2.0;  // the refined path checks too (its first pass is a stochastic pass)
  params.sampling.density_ratio = 0.5;
  CHECK_THROWS_AS(decimate(mesh, *layout, params), std::invalid_argument);
}

// A decimation given no flood caches (a mesh made to be decimated once) leaves none of its draw's
// per-vertex tables on the layout: they would sit under the next stages' peak. One given caches
// keeps them for the next draw (a slider), and both give the same result.
TEST_CASE("a decimation without flood caches keeps no draw tables on the layout, with the same result") {
  const auto arrays = topstoc_test::torus(60, 40);
  const Mesh mesh(arrays.positions, arrays.triangles.data(), arrays.num_triangles());
  const auto once = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
  const auto kept = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
  FloodCachePool pool;
  for (double refine : {0.0, 2.0}) {
    for (int32_t target : {300, 290}) {  // the second: a slider's next draw with the same seed
      CAPTURE(refine);
      CAPTURE(target);
      DecimateParams params;
      params.target_vertices = target;
      params.refine = refine;
      params.sampling.seed = 3;
      const DecimateResult plain = decimate(mesh, *once, params);
      CHECK(!once->sampling_table.get());
      CHECK(!once->selection_uniforms.get());
      CHECK(!once->candidate_order.get());
      params.flood_caches = &pool;
      const DecimateResult slider = decimate(mesh, *kept, params);
      CHECK(bool(kept->sampling_table.get()));
      CHECK(bool(kept->selection_uniforms.get()));
      if (target == 290) CHECK(bool(kept->candidate_order.get()));
      CHECK(plain.vertices == slider.vertices);
      CHECK(plain.triangles == slider.triangles);
      CHECK(plain.labels == slider.labels);
    }
  }
}
