// Mesh preparation reports its steps through the progress mechanism and stops when told to.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

using topstoc::Mesh;

TEST_CASE("mesh preparation reports every step in order, from 0 to its last share") {
  const auto a = topstoc_test::torus(40, 20);
  std::vector<std::string> stages;
  std::vector<double> fractions;
  const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles(), [&](double fraction, const char* stage) {
    stages.emplace_back(stage);
    fractions.push_back(fraction);
    return true;
  });
  CHECK(mesh.num_faces() == 1600);
  CHECK(stages == std::vector<std::string>{"validate", "order", "adjacency", "normals and weights", "components"});
  for (size_t i = 1; i < fractions.size(); ++i) CHECK(fractions[i] > fractions[i - 1]);
  CHECK(fractions.front() == 0.0);
  CHECK(fractions.back() < 1.0);
}

TEST_CASE("a progress callback answering false stops the preparation with Cancelled") {
  const auto a = topstoc_test::torus(40, 20);
  for (const std::string stop_at : {"validate", "adjacency", "components"}) {
    std::vector<std::string> stages;
    auto callback = [&](double, const char* stage) {
      stages.emplace_back(stage);
      return stages.back() != stop_at;
    };
    CHECK_THROWS_AS(Mesh(a.positions, a.triangles.data(), a.num_triangles(), callback), topstoc::Cancelled);
    CHECK(stages.back() == stop_at);  // nothing ran after the step that was refused
  }
  // Without a callback nothing changes.
  const Mesh plain(a.positions, a.triangles.data(), a.num_triangles());
  CHECK(plain.num_faces() == 1600);
}
