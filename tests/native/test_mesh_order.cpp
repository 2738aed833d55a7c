// The prepared vertex order is the Z-order (Morton) curve: vertices sorted by their interleaved
// 21-bit coordinates in the bounding cube, ties by the caller's vertex id. Compared with that
// definition computed bit by bit here, on meshes large enough for the parallel path.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

namespace {

using topstoc_test::Arrays;

// The definition: each coordinate scaled by the cube's side into 0..2^21-1; bit i of axis a's
// value becomes bit 3i + a of the key.
std::vector<int32_t> morton_order(const std::vector<double>& positions) {
  const size_t n = positions.size() / 3;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = hi[a] = positions[a];
    for (size_t v = 0; v < n; ++v) lo[a] = std::min(lo[a], positions[3 * v + a]), hi[a] = std::max(hi[a], positions[3 * v + a]);
  }
  const double side = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  std::vector<std::pair<uint64_t, int32_t>> keyed(n);
  for (size_t v = 0; v < n; ++v) {
    uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const uint64_t q = uint64_t((positions[3 * v + a] - lo[a]) / side * 2097151.0);
      for (int bit = 0; bit < 21; ++bit) key |= ((q >> bit) & 1) << (3 * bit + a);
    }
    keyed[v] = {key, int32_t(v)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

// The same mesh with its vertices renumbered at random, so that ties are not already in order.
Arrays shuffled(const Arrays& a, uint32_t seed) {
  const int32_t n = int32_t(a.positions.size() / 3);
  std::vector<int32_t> to(n);
  std::iota(to.begin(), to.end(), 0);
  std::mt19937 random(seed);
  std::shuffle(to.begin(), to.end(), random);
  Arrays out;
  out.positions.resize(a.positions.size());
  for (int32_t v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) out.positions[3 * size_t(to[v]) + c] = a.positions[3 * size_t(v) + c];
  for (const int32_t v : a.triangles) out.triangles.push_back(to[v]);
  return out;
}

std::vector<int32_t> prepared_order(const Arrays& a) {
  const topstoc::Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  return std::vector<int32_t>(mesh.vertex_source().begin(), mesh.vertex_source().end());
}

}  // namespace

TEST_CASE("the prepared vertex order is the Morton order, ties by vertex id") {
  // 109,561 vertices (above the parallel threshold), a few to each cell of the coarse sort.
  Arrays wavy = topstoc_test::grid(330, 330);
  for (size_t v = 0; v < wavy.positions.size() / 3; ++v)
    wavy.positions[3 * v + 2] = 3.0 * std::sin(0.05 * wavy.positions[3 * v]) * std::cos(0.07 * wavy.positions[3 * v + 1]);
  const Arrays a = shuffled(wavy, 1);
  CHECK(prepared_order(a) == morton_order(a.positions));

  SUBCASE("one far vertex puts the whole grid in one cell of the coarse sort") {
    Arrays far = a;
    const int32_t n = int32_t(far.positions.size() / 3);
    far.positions.insert(far.positions.end(), {1e6, 1e6, 0.0, 1e6 + 1, 1e6, 0.0, 1e6, 1e6 + 1, 0.0});
    far.triangles.insert(far.triangles.end(), {n, n + 1, n + 2});
    CHECK(prepared_order(far) == morton_order(far.positions));
  }
  SUBCASE("vertices at one position keep the caller's order") {
    Arrays stacked = topstoc_test::grid(330, 330);
    for (double& x : stacked.positions) x = std::floor(x / 4.0);  // 16 vertices at each point
    const Arrays b = shuffled(stacked, 2);
    CHECK(prepared_order(b) == morton_order(b.positions));
  }
}

TEST_CASE("the caller-to-internal vertex map, made on first use, is the inverse of the vertex order") {
  // Shuffled, with a vertex in no triangle and a dropped (repeated-vertex) triangle.
  Arrays a = shuffled(topstoc_test::grid(330, 330), 3);
  const int32_t n = int32_t(a.positions.size() / 3);
  a.positions.insert(a.positions.end(), {500.0, 500.0, 1.0});
  a.triangles.insert(a.triangles.end(), {0, 0, 1});
  const topstoc::Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  REQUIRE(mesh.num_vertices() == n + 1);
  // A few caller ids (repeats and the isolated vertex among them) found before the map is made,
  // then read off it: the same ids.
  const std::vector<int32_t> few = {n, 7, 0, 7, n / 2, 1};
  const std::vector<int32_t> scanned = mesh.internal_ids(few);
  CHECK_THROWS_AS(mesh.internal_ids({n + 1}), std::out_of_range);
  CHECK_THROWS_AS(mesh.internal_ids({-1}), std::out_of_range);
  const void* seen[2] = {nullptr, nullptr};
  std::thread other([&] { seen[1] = &mesh.vertex_index(); });  // two threads asking at once
  seen[0] = &mesh.vertex_index();
  other.join();
  CHECK(seen[0] == seen[1]);
  const auto& index = mesh.vertex_index();
  const auto& source = mesh.vertex_source();
  REQUIRE(index.size() == size_t(n + 1));
  int32_t wrong = 0;
  for (int32_t v = 0; v <= n; ++v) wrong += source[index[v]] != v;
  CHECK(wrong == 0);
  CHECK(mesh.internal_ids(few) == scanned);
  for (size_t i = 0; i < few.size(); ++i) CHECK(scanned[i] == index[few[i]]);
  // The internal ids of each kept face are the caller's triangle read through the map.
  for (int32_t f = 0; f < mesh.num_faces(); f += 97)
    for (int c = 0; c < 3; ++c)
      CHECK(mesh.faces()[3 * size_t(f) + c] == index[a.triangles[3 * size_t(mesh.face_source()[f]) + c]]);
}
