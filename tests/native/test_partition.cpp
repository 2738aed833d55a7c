// The partition check (partition.hpp): accepts a clustering that reproduces the input, and
// rejects hand-made clusterings whose emitted triangles cannot be homeomorphic to the input,
// naming clusters to split or samples to add.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <numeric>
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
