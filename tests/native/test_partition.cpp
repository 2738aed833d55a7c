// The partition check (partition.hpp): accepts a clustering that reproduces the input, and
// rejects hand-made clusterings whose emitted triangles cannot be homeomorphic to the input,
// naming clusters to split or samples to add.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "meshes.hpp"
#include "topstoc/decimate/clustering.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/decimate/partition.hpp"

using namespace topstoc;

namespace {

struct Checked {
  Partition partition;
  int32_t num_faces;
};

// Floods from `caller_samples` (the caller's vertex ids) and checks the partition.
Checked check(const topstoc_test::Arrays& a, const std::vector<int32_t>& caller_samples) {
  const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  const auto layout = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
  std::vector<int32_t> samples;
  for (int32_t v : caller_samples) samples.push_back(mesh.vertex_index()[v]);
  Clustering clustering;
  flood(mesh, *layout, samples, clustering);
  const std::vector<uint8_t> required(mesh.num_vertices(), 0);
  return {check_partition(mesh, *layout, samples, clustering, required, true), mesh.num_faces()};
}

// Each triangle as its sorted vertex set.
std::set<std::array<int32_t, 3>> triangle_sets(const std::vector<int32_t>& t) {
  std::set<std::array<int32_t, 3>> out;
  for (size_t i = 0; i < t.size(); i += 3) {
    std::array<int32_t, 3> s{t[i], t[i + 1], t[i + 2]};
    std::sort(s.begin(), s.end());
    out.insert(s);
  }
  return out;
}

void check_rejected(const Checked& c) {
  CHECK(c.partition.issues.topological() > 0);
  // A rejection says where to refine: clusters to split or vertices to add as samples.
  CHECK(c.partition.split_clusters.size() + c.partition.new_samples.size() > 0);
}

}  // namespace

TEST_CASE("every vertex a sample: accepted, and the triangles are the input's") {
  for (const auto& arrays : {topstoc_test::torus(8, 5), topstoc_test::octahedron(), topstoc_test::grid(4, 3)}) {
    const int32_t n = int32_t(arrays.positions.size() / 3);
    std::vector<int32_t> samples(n);
    std::iota(samples.begin(), samples.end(), 0);  // rank r = caller vertex r
    const Checked c = check(arrays, samples);
    CHECK(c.partition.issues.topological() == 0);
    CHECK(c.partition.issues.sliver == 0);
    CHECK(triangle_sets(c.partition.triangles) == triangle_sets(arrays.triangles));
  }
}

TEST_CASE("rejected: a torus cut into three bands (annuli, no triangle survives)") {
  // torus(12, 3): one sample every fourth ring, so each cluster wraps around the tube.
  check_rejected(check(topstoc_test::torus(12, 3), {0, 4 * 3, 8 * 3}));
}

TEST_CASE("rejected: a torus with too few clusters to carry its handle") {
  // Four clusters can triangulate a sphere at best; a torus needs at least seven vertices.
  check_rejected(check(topstoc_test::torus(10, 8), {0, 2 * 8 + 4, 5 * 8, 7 * 8 + 4}));
}

TEST_CASE("rejected: an octahedron in three clusters (the output would be a doubled triangle)") {
  check_rejected(check(topstoc_test::octahedron(), {0, 5, 1}));
}

TEST_CASE("rejected: a grid (a disk) in two clusters") {
  check_rejected(check(topstoc_test::grid(6, 6), {0, 48}));
}

namespace {

void check_same(const Partition& a, const Partition& b) {
  CHECK(a.triangles == b.triangles);
  CHECK(a.source_face == b.source_face);
  CHECK(a.split_clusters == b.split_clusters);
  CHECK(a.new_samples == b.new_samples);
  CHECK(a.absorbed == b.absorbed);
  const auto& x = a.issues;
  const auto& y = b.issues;
  CHECK(std::vector<int32_t>{x.unreached, x.non_disk, x.bad_edge, x.duplicate, x.bad_link, x.short_loop, x.isolated,
                             x.bad_component, x.sliver, x.pillows, x.absorbed} ==
        std::vector<int32_t>{y.unreached, y.non_disk, y.bad_edge, y.duplicate, y.bad_link, y.short_loop, y.isolated,
                             y.bad_component, y.sliver, y.pillows, y.absorbed});
}

}  // namespace

// The meshes the incremental checks are compared on: a torus without features and with two
// regions (closed feature curves), and a grid whose column i = 7 is a border.
struct IncrementalCases {
  struct Case {
    const Mesh* mesh;
    std::shared_ptr<const FeatureLayout> layout;
  };
  topstoc_test::Arrays torus_arrays = topstoc_test::torus(24, 16), grid_arrays = topstoc_test::grid(14, 10);
  Mesh torus{torus_arrays.positions, torus_arrays.triangles.data(), torus_arrays.num_triangles()};
  Mesh grid{grid_arrays.positions, grid_arrays.triangles.data(), grid_arrays.num_triangles()};
  std::vector<Case> cases;

  IncrementalCases() {
    std::vector<int32_t> halves(torus.num_faces());
    for (int32_t f = 0; f < torus.num_faces(); ++f) halves[f] = torus.position(torus.faces()[3 * size_t(f)])[0] > 0;
    std::vector<int32_t> border;  // caller vertex pairs
    for (int32_t j = 0; j < 10; ++j) border.insert(border.end(), {7 * 11 + j, 7 * 11 + j + 1});
    cases = {{&torus, build_feature_layout(torus, nullptr, 0, nullptr, 0, 0.0)},
             {&torus, build_feature_layout(torus, halves.data(), int64_t(halves.size()), nullptr, 0, 0.0)},
             {&grid, build_feature_layout(grid, nullptr, 0, border.data(), int64_t(border.size() / 2), 0.0)}};
  }
  const std::vector<Case>& all() const { return cases; }
  std::vector<Case> with_features() const { return {cases[1], cases[2]}; }
};

TEST_CASE("a check after flood_add evaluates only the changed links and finds what a check from scratch finds") {
  // Few samples at first (many issues), then a few more per round, as the repair rounds add
  // them: every round's incremental check must equal a full one of the same clustering.
  const IncrementalCases cases;
  int64_t incremental_rounds = 0;
  for (const auto& kase : cases.all()) {
    const Mesh& mesh = *kase.mesh;
    for (uint32_t seed = 1; seed <= 60; ++seed) {
      std::mt19937 random(seed);
      std::vector<int32_t> samples = topstoc_test::random_samples(mesh.num_vertices(), 4 + int32_t(seed % 5), random);
      Clustering clustering;
      flood(mesh, *kase.layout, samples, clustering);
      const std::vector<uint8_t> required(mesh.num_vertices(), 0);
      CheckState state;
      for (int round = 0; round < 10; ++round) {
        const bool slivers = round < 6;
        const Partition kept = check_partition(mesh, *kase.layout, samples, clustering, required, slivers, nullptr, &state);
        const Partition fresh = check_partition(mesh, *kase.layout, samples, clustering, required, slivers);
        check_same(kept, fresh);
        incremental_rounds += round > 0 && state.links_valid;
        // Add what the check asks for, or else a few unsampled vertices.
        std::vector<uint8_t> sampled(mesh.num_vertices(), 0);
        for (int32_t v : samples) sampled[v] = 1;
        std::vector<int32_t> added;
        for (int32_t v : kept.new_samples)
          if (!sampled[v]) sampled[v] = 1, added.push_back(v);
        for (int32_t tries = 0; added.size() < 3 && tries < 100; ++tries) {
          const int32_t v = int32_t(random() % uint32_t(mesh.num_vertices()));
          if (!sampled[v]) sampled[v] = 1, added.push_back(v);
        }
        if (added.empty()) break;
        const int32_t first_new = int32_t(samples.size());
        samples.insert(samples.end(), added.begin(), added.end());
        flood_add(mesh, *kase.layout, samples, first_new, clustering, &state.changed);
      }
    }
  }
  CHECK(incremental_rounds > 200);
}

TEST_CASE("a check after flood_update, given the old flood's triangles and links in the new ranks, finds what a check from scratch finds") {
  // The slider's case (flood_cache.hpp): a kept flood of other samples is updated, and its
  // emitted triangles are taken over except around the vertices that changed, and what its
  // check found per sample except for the samples whose links changed.
  // The old check's zero-area flags come along too (the flat grid has collinear samples).
  // Every other draw, the samples left without a triangle become control points, which must
  // then count as isolated (a slider frame's control points follow its rate).
  const IncrementalCases cases;
  int64_t patched = 0, patched_with_slivers = 0, newly_required = 0;
  for (const auto& kase : cases.all()) {
    const Mesh& mesh = *kase.mesh;
    const std::vector<uint8_t> none_required(mesh.num_vertices(), 0);
    for (uint32_t seed = 1; seed <= 240; ++seed) {
      std::mt19937 random(seed);
      auto pool = topstoc_test::random_samples(mesh.num_vertices(), 70, random);
      std::vector<int32_t> old_samples(pool.begin(), pool.begin() + 55 + int32_t(seed % 5));
      // The new draw keeps most old samples, drops a few and adds a few (both lists increasing;
      // few enough that the check re-tests around the changed vertices only).
      std::vector<int32_t> samples;
      for (size_t i = 0; i < old_samples.size(); ++i)
        if (random() % 40 != 0) samples.push_back(old_samples[i]);
      for (size_t i = old_samples.size(); i < pool.size(); ++i)
        if (random() % 6 == 0) samples.push_back(pool[i]);
      std::sort(old_samples.begin(), old_samples.end());
      std::sort(samples.begin(), samples.end());
      Clustering clustering;
      flood(mesh, *kase.layout, old_samples, clustering);
      CheckState first;
      check_partition(mesh, *kase.layout, old_samples, clustering, none_required, true, nullptr, &first);
      CheckState state = first;
      std::vector<int32_t> new_rank;
      flood_update(mesh, *kase.layout, old_samples, samples, clustering, &state.changed, &new_rank);
      std::vector<uint8_t> required = none_required;
      if (seed % 2 == 0) {
        const Partition absorbing = check_partition(mesh, *kase.layout, samples, clustering, none_required, true);
        for (size_t s = 0; s < absorbing.absorbed.size(); ++s) required[samples[s]] = absorbing.absorbed[s];
      }
      state.renumber(new_rank, int32_t(samples.size()));
      const bool can_patch = state.valid && state.emitted_valid && state.changed.size() <= size_t(mesh.num_vertices() / 16);
      const Partition kept = check_partition(mesh, *kase.layout, samples, clustering, required, true, nullptr, &state);
      const Partition fresh = check_partition(mesh, *kase.layout, samples, clustering, required, true);
      check_same(kept, fresh);
      patched += can_patch && kept.issues.unreached == 0;
      patched_with_slivers += can_patch && kept.issues.unreached == 0 && fresh.issues.sliver > 0;
      newly_required += can_patch && fresh.issues.isolated > 0;
    }
  }
  CHECK(patched > 30);
  CHECK(patched_with_slivers > 5);
  CHECK(newly_required > 3);
}

TEST_CASE("a check after flood_update that leaves a small component without samples finds it unreached") {
  // A torus and a lone triangle; the update drops the triangle's only sample. Its three
  // vertices are emptied and stay so: the check that takes the kept triangles over must still
  // find them (it scans only the changed vertices).
  auto arrays = topstoc_test::torus(24, 16);
  const int32_t first = int32_t(arrays.positions.size() / 3);
  arrays.positions.insert(arrays.positions.end(), {5, 0, 0, 6, 0, 0, 5, 1, 0});
  arrays.triangles.insert(arrays.triangles.end(), {first, first + 1, first + 2});
  const Mesh mesh(arrays.positions, arrays.triangles.data(), arrays.num_triangles());
  const auto layout = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
  const std::vector<uint8_t> required(mesh.num_vertices(), 0);
  const int32_t lone = mesh.vertex_index()[first];  // the triangle's first vertex, in the mesh's order
  std::mt19937 random(7);
  std::vector<int32_t> samples;
  for (int32_t v : topstoc_test::random_samples(mesh.num_vertices(), 80, random))
    if (mesh.component()[v] == mesh.component()[mesh.vertex_index()[0]]) samples.push_back(v);
  std::vector<int32_t> old_samples = samples;
  old_samples.push_back(lone);
  std::sort(old_samples.begin(), old_samples.end());
  std::sort(samples.begin(), samples.end());
  Clustering clustering;
  flood(mesh, *layout, old_samples, clustering);
  CheckState state;
  const Partition before = check_partition(mesh, *layout, old_samples, clustering, required, false, nullptr, &state);
  REQUIRE(before.issues.unreached == 0);
  REQUIRE(state.emitted_valid);
  std::vector<int32_t> new_rank;
  state.changed.clear();
  flood_update(mesh, *layout, old_samples, samples, clustering, &state.changed, &new_rank);
  state.renumber(new_rank, int32_t(samples.size()));
  REQUIRE(state.changed.size() <= size_t(mesh.num_vertices() / 16));  // the patched path
  const Partition kept = check_partition(mesh, *layout, samples, clustering, required, false, nullptr, &state);
  CHECK(kept.issues.unreached == 3);
  check_same(kept, check_partition(mesh, *layout, samples, clustering, required, false));
}

TEST_CASE("a check after relabelling feature vertices by hand finds what a check from scratch finds") {
  // Vertices on feature curves moved to a neighbour's cluster, a few at a time: this changes
  // the triangle count expected between feature pairs, sometimes with no emitted triangle
  // changing around the vertex, which the flood_add rounds above rarely do.
  const IncrementalCases cases;
  for (const auto& kase : cases.with_features()) {
    const Mesh& mesh = *kase.mesh;
    const auto& ao = mesh.adjacency_offsets();
    const auto& adj = mesh.adjacency();
    std::vector<int32_t> on_feature;
    for (int32_t v = 0; v < mesh.num_vertices(); ++v)
      if (kase.layout->is_feature_vertex(v)) on_feature.push_back(v);
    REQUIRE(on_feature.size() > 10);
    for (uint32_t seed = 1; seed <= 40; ++seed) {
      std::mt19937 random(seed);
      const auto samples = topstoc_test::random_samples(mesh.num_vertices(), 12 + int32_t(seed % 9), random);
      Clustering clustering;
      flood(mesh, *kase.layout, samples, clustering);
      const std::vector<uint8_t> required(mesh.num_vertices(), 0);
      CheckState state;
      for (int round = 0; round < 8; ++round) {
        const Partition kept = check_partition(mesh, *kase.layout, samples, clustering, required, true, nullptr, &state);
        const Partition fresh = check_partition(mesh, *kase.layout, samples, clustering, required, true);
        check_same(kept, fresh);
        if (!state.links_valid) break;  // an unreached vertex: nothing to compare incrementally
        for (int moved = 0; moved < 3; ++moved) {
          const int32_t v = on_feature[random() % on_feature.size()];
          const int32_t u = adj[ao[v] + int32_t(random() % uint32_t(ao[v + 1] - ao[v]))];
          if (clustering.dist(v) == 0 || clustering.label(u) == clustering.label(v)) continue;  // samples stay
          clustering.relabel(v, clustering.label(u));
          state.changed.push_back(v);
        }
      }
    }
  }
}

// Six times V - E + F of each cluster's vertices, the edges between two of them and the faces
// of three, by a scan of every face: the Euler characteristic of a cluster where every vertex
// is one sector and every edge one copy (no feature edges but borders).
std::vector<int64_t> euler6_by_scan(const Mesh& mesh, const Clustering& c, int32_t k) {
  std::vector<int64_t> chi6(k, 0);
  std::set<std::pair<int32_t, int32_t>> edges;
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* t = &mesh.faces()[3 * size_t(f)];
    for (int j = 0; j < 3; ++j) edges.insert({std::min(t[j], t[(j + 1) % 3]), std::max(t[j], t[(j + 1) % 3])});
    if (c.label(t[0]) == c.label(t[1]) && c.label(t[1]) == c.label(t[2])) chi6[c.label(t[0])] += 6;
  }
  for (const auto& [a, b] : edges)
    if (c.label(a) == c.label(b)) chi6[c.label(a)] -= 6;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    if (c.label(v) >= 0) chi6[c.label(v)] += 6;
  return chi6;
}

TEST_CASE("each cluster's Euler characteristic is V - E + F of its own vertices, edges and faces") {
  std::mt19937 random(7);
  topstoc_test::Arrays holed = topstoc_test::grid(20, 15);
  holed.triangles.erase(holed.triangles.begin() + 300, holed.triangles.begin() + 306);  // a hole
  int32_t compared = 0;
  for (const topstoc_test::Arrays& a : {topstoc_test::torus(30, 20), topstoc_test::grid(20, 15), holed}) {
    const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
    const auto layout = build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
    for (int32_t count : {1, 5, 40, 200}) {
      const std::vector<int32_t> samples = topstoc_test::random_samples(mesh.num_vertices(), count, random);
      Clustering clustering;
      flood(mesh, *layout, samples, clustering);
      bool reached = true;  // (the check asks this first: a flood along borders can leave some)
      for (int32_t v = 0; v < mesh.num_vertices(); ++v) reached = reached && clustering.label(v) >= 0;
      if (!reached) continue;
      CHECK(cluster_euler6(mesh, *layout, count, clustering) == euler6_by_scan(mesh, clustering, count));
      ++compared;
    }
  }
  CHECK(compared >= 6);  // the torus's four and some of the bordered grids'
}
