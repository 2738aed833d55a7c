// Clustering: flood() against the definition (each vertex joins the sample of least
// (hop distance, rank), by a breadth-first search per sample), and flood_add() against flood()
// on the whole sample list, and flood_update() against flood() on the new list, as
// clustering.hpp promises; and flood_drop_tail() against flood() on the samples it keeps.
#include <doctest/doctest.h>

#include <algorithm>
#include <climits>
#include <numeric>
#include <queue>
#include <random>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/decimate/clustering.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/io/io.hpp"

using namespace topstoc;

namespace {

Mesh make_mesh(const topstoc_test::Arrays& a) { return Mesh(a.positions, a.triangles.data(), a.num_triangles()); }

std::shared_ptr<const FeatureLayout> no_features(const Mesh& mesh) {
  return build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
}

// The 14 x 10 grid's boundary and, as a border, its column i = 7 (caller vertex pairs).
std::shared_ptr<const FeatureLayout> column_border(const Mesh& mesh) {
  std::vector<int32_t> border;
  for (int32_t j = 0; j < 10; ++j) border.insert(border.end(), {7 * 11 + j, 7 * 11 + j + 1});
  return build_feature_layout(mesh, nullptr, 0, border.data(), int64_t(border.size() / 2), 0.0);
}

// The definition, without features: a breadth-first search from every sample.
Clustering brute_clustering(const Mesh& mesh, const std::vector<int32_t>& samples) {
  const int32_t n = mesh.num_vertices();
  std::vector<int32_t> label(n, -1), dist(n, INT32_MAX);
  const auto& offsets = mesh.adjacency_offsets();
  const auto& adjacency = mesh.adjacency();
  for (int32_t rank = 0; rank < int32_t(samples.size()); ++rank) {
    std::vector<int32_t> hops(n, -1);
    std::queue<int32_t> queue;
    hops[samples[rank]] = 0;
    queue.push(samples[rank]);
    while (!queue.empty()) {
      const int32_t v = queue.front();
      queue.pop();
      for (int32_t s = offsets[v]; s < offsets[v + 1]; ++s)
        if (hops[adjacency[s]] < 0) hops[adjacency[s]] = hops[v] + 1, queue.push(adjacency[s]);
    }
    for (int32_t v = 0; v < n; ++v)
      if (hops[v] >= 0 && (hops[v] < dist[v] || (hops[v] == dist[v] && rank < label[v])))
        dist[v] = hops[v], label[v] = rank;
  }
  Clustering c;
  for (int32_t v = 0; v < n; ++v) c.key.push_back(label[v] < 0 ? kUnreachedKey : cluster_key(dist[v], label[v]));
  return c;
}

// The sample vertex and distance of every vertex (what stays when ranks are renumbered).
std::vector<std::pair<int32_t, int32_t>> identities(const Clustering& c, const std::vector<int32_t>& samples) {
  std::vector<std::pair<int32_t, int32_t>> out;
  for (int32_t v = 0; v < c.num_vertices(); ++v)
    out.push_back(c.label(v) < 0 ? std::make_pair(-1, -1) : std::make_pair(samples[c.label(v)], c.dist(v)));
  return out;
}

// `changed` (repeats allowed) names every vertex whose sample or distance differs between the
// two clusterings, and only those.
void check_changed(std::vector<int32_t> changed, const Clustering& before, const std::vector<int32_t>& before_samples,
                   const Clustering& after, const std::vector<int32_t>& after_samples) {
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  const auto was = identities(before, before_samples), is = identities(after, after_samples);
  std::vector<int32_t> differ;
  for (int32_t v = 0; v < before.num_vertices(); ++v)
    if (was[v] != is[v]) differ.push_back(v);
  CHECK(changed == differ);
}

void check_flood_add_equals_flood(const Mesh& mesh, const FeatureLayout& layout, std::mt19937& random) {
  const int32_t n = mesh.num_vertices();
  for (int round = 0; round < 10; ++round) {
    const int32_t total = 2 + int32_t(random() % std::max(2, n / 4));
    const auto samples = topstoc_test::random_samples(n, total, random);
    const int32_t first_new = 1 + int32_t(random() % (total - 1));
    Clustering whole, incremental;
    flood(mesh, layout, samples, whole);
    const std::vector<int32_t> first(samples.begin(), samples.begin() + first_new);
    flood(mesh, layout, first, incremental);
    const Clustering before = incremental;
    std::vector<int32_t> changed;
    flood_add(mesh, layout, samples, first_new, incremental, &changed);
    CHECK(incremental.key == whole.key);
    check_changed(changed, before, first, whole, samples);
  }
}

// A random sorted subset of [0, n) of `count` vertices.
std::vector<int32_t> sorted_samples(int32_t n, int32_t count, std::mt19937& random) {
  auto ids = topstoc_test::random_samples(n, count, random);
  std::sort(ids.begin(), ids.end());
  return ids;
}

// Old and new lists that overlap as slider steps do (a few percent replaced), or not at all.
void check_flood_update_equals_flood(const Mesh& mesh, const FeatureLayout& layout, std::mt19937& random) {
  const int32_t n = mesh.num_vertices();
  for (int round = 0; round < 12; ++round) {
    const int32_t count = 1 + int32_t(random() % std::max(2, n / 4));
    const auto old_samples = sorted_samples(n, count, random);
    std::vector<int32_t> samples;
    const uint32_t keep_percent = round % 3 == 0 ? 0 : 80 + random() % 21;  // share of old samples kept
    for (int32_t v : old_samples)
      if (random() % 100 < keep_percent) samples.push_back(v);
    std::vector<uint8_t> listed(n, 0);
    for (int32_t v : samples) listed[v] = 1;
    int32_t add = int32_t(random() % (count / 4 + 2));
    for (int32_t v : topstoc_test::random_samples(n, n, random))
      if (add > 0 && !listed[v]) listed[v] = 1, samples.push_back(v), --add;
    if (samples.empty()) samples.push_back(old_samples.front());
    std::sort(samples.begin(), samples.end());
    Clustering whole, updated;
    flood(mesh, layout, samples, whole);
    flood(mesh, layout, old_samples, updated);
    const Clustering before = updated;
    std::vector<int32_t> changed;
    flood_update(mesh, layout, old_samples, samples, updated, &changed);
    CHECK(updated.key == whole.key);
    check_changed(changed, before, old_samples, whole, samples);
  }
}

}  // namespace

TEST_CASE("flood gives every vertex the sample of least (hops, rank), as a search per sample does") {
  std::mt19937 random(23);
  const Mesh mesh = make_mesh(topstoc_test::torus(12, 9));
  const auto layout = no_features(mesh);
  for (int round = 0; round < 10; ++round) {
    const auto samples = topstoc_test::random_samples(mesh.num_vertices(), 1 + int32_t(random() % 20), random);
    Clustering c;
    flood(mesh, *layout, samples, c);
    const Clustering expected = brute_clustering(mesh, samples);
    CHECK(c.key == expected.key);
  }
}

// Large enough for the threads to share a level (a frontier of kParallelMin / 16 vertices or
// more): each thread owns a range of vertex ids and hands the lowerings of others' vertices
// over after the level. Every team size must give the one-thread keys and crossing edges.
TEST_CASE("flood on several threads gives the keys and crossing edges of one thread") {
  std::mt19937 random(31);
  const Mesh mesh = make_mesh(topstoc_test::torus(300, 160));  // 48,000 vertices
  const auto layout = no_features(mesh);
  const int before = max_threads();
  for (const int32_t count : {9000, 1500}) {  // the first level parallel, or only later ones
    const auto samples = topstoc_test::random_samples(mesh.num_vertices(), count, random);
    auto run = [&](int threads, std::vector<int32_t>& cross) {
      set_max_threads(threads);
      Clustering c;
      flood(mesh, *layout, samples, c, &cross);
      std::sort(cross.begin(), cross.end());
      return c;
    };
    std::vector<int32_t> cross_one, cross_many;
    const Clustering one = run(1, cross_one);
    CHECK(std::adjacent_find(cross_one.begin(), cross_one.end()) == cross_one.end());  // each edge once
    for (const int threads : {2, 3, 7}) {
      const Clustering many = run(threads, cross_many);
      CHECK(many.key == one.key);
      CHECK(cross_many == cross_one);
    }
  }
  set_max_threads(before);
}

// Both incremental updates against a fresh flood, on each mesh.
void check_updates(const Mesh& mesh, const FeatureLayout& layout, std::mt19937& random) {
  check_flood_add_equals_flood(mesh, layout, random);
  check_flood_update_equals_flood(mesh, layout, random);
}

TEST_CASE("flood_add and flood_update give exactly what flood gives on the whole new sample list") {
  std::mt19937 random(29);
  SUBCASE("torus, no features") {
    const Mesh mesh = make_mesh(topstoc_test::torus(20, 11));
    check_updates(mesh, *no_features(mesh), random);
  }
  SUBCASE("grid with a boundary, a border curve across it") {
    const Mesh mesh = make_mesh(topstoc_test::grid(14, 10));
    const auto layout = column_border(mesh);
    CHECK(layout->feature_edges.size() == 2 * (14 + 10) + 10);  // the boundary and the border
    check_updates(mesh, *layout, random);
  }
  SUBCASE("a genus-2 test mesh (tests/data)") {
    const MeshFile file = read_mesh_path(TOPSTOC_TEST_DATA "/genus_positive/cgal_eight.off");
    const Mesh mesh(file.vertices, file.triangles.data(), file.num_triangles());
    check_updates(mesh, *no_features(mesh), random);
  }
  SUBCASE("a mesh with holes (tests/data): boundary curves") {
    const MeshFile file = read_mesh_path(TOPSTOC_TEST_DATA "/open_boundary/cgal_elephant-with-holes.off");
    const Mesh mesh(file.vertices, file.triangles.data(), file.num_triangles());
    for (int i = 0; i < 4; ++i) check_updates(mesh, *no_features(mesh), random);
  }
  SUBCASE("two tori: a piece can lose all its samples") {
    auto a = topstoc_test::torus(9, 7);
    const auto b = topstoc_test::torus(6, 5, 1.0, 0.3);
    const int32_t offset = int32_t(a.positions.size() / 3);
    for (size_t i = 0; i < b.positions.size(); ++i) a.positions.push_back(b.positions[i] + (i % 3 == 0 ? 5.0 : 0.0));
    for (int32_t v : b.triangles) a.triangles.push_back(v + offset);
    const Mesh mesh = make_mesh(a);
    for (int i = 0; i < 4; ++i) check_updates(mesh, *no_features(mesh), random);
  }
}

TEST_CASE("flood_update refuses lists that are not increasing vertex ids") {
  const Mesh mesh = make_mesh(topstoc_test::torus(8, 6));
  const auto layout = no_features(mesh);
  Clustering c;
  flood(mesh, *layout, {1, 5, 9}, c);
  CHECK_THROWS_AS(flood_update(mesh, *layout, {1, 5, 9}, {9, 5}, c), std::invalid_argument);
  CHECK_THROWS_AS(flood_update(mesh, *layout, {1, 5, 9}, {1, 1000}, c), std::invalid_argument);
}

namespace {

// A draw (increasing vertex ids) followed by repair samples appended in any order, as a
// decimation makes them: dropping the appended ones gives exactly the flood of the draw.
void check_drop_tail(const Mesh& mesh, const FeatureLayout& layout, std::mt19937& random) {
  const int32_t n = mesh.num_vertices();
  for (int round = 0; round < 6; ++round) {
    std::vector<int32_t> all = topstoc_test::random_samples(n, std::max(2, n / (8 + 4 * round)), random);
    const int32_t drawn = std::max<int32_t>(1, int32_t(all.size()) * (round + 1) / 8);
    std::sort(all.begin(), all.begin() + drawn);
    std::vector<int32_t> draw(all.begin(), all.begin() + drawn);
    Clustering fresh, repaired;
    flood(mesh, layout, draw, fresh);
    flood(mesh, layout, draw, repaired);
    flood_add(mesh, layout, all, drawn, repaired);
    flood_drop_tail(mesh, layout, drawn, int32_t(all.size()), repaired);
    CHECK(repaired.key == fresh.key);
  }
}

}  // namespace

TEST_CASE("flood_drop_tail gives back exactly the flood of the samples before the appended ones") {
  std::mt19937 random(31);
  SUBCASE("torus, no features") {
    const Mesh mesh = make_mesh(topstoc_test::torus(20, 11));
    check_drop_tail(mesh, *no_features(mesh), random);
  }
  SUBCASE("grid with a boundary, a border curve across it") {
    const Mesh mesh = make_mesh(topstoc_test::grid(14, 10));
    check_drop_tail(mesh, *column_border(mesh), random);
  }
  SUBCASE("a mesh with holes (tests/data): boundary curves") {
    const MeshFile file = read_mesh_path(TOPSTOC_TEST_DATA "/open_boundary/cgal_elephant-with-holes.off");
    const Mesh mesh(file.vertices, file.triangles.data(), file.num_triangles());
    check_drop_tail(mesh, *no_features(mesh), random);
  }
  const Mesh mesh = make_mesh(topstoc_test::torus(8, 6));
  Clustering c;
  flood(mesh, *no_features(mesh), {1, 5, 9}, c);
  CHECK_THROWS_AS(flood_drop_tail(mesh, *no_features(mesh), 4, 3, c), std::invalid_argument);
}
