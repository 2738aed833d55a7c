// Vertex areas (a third of the area of the triangles around each vertex), built on first use:
// against the triangles' areas computed here from the caller's arrays, and asked for by two
// threads at once.
#include <doctest/doctest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

using topstoc::Mesh;

namespace {

// Per caller vertex: a third of the area of its triangles, from the arrays as given.
std::vector<double> areas_by_hand(const topstoc_test::Arrays& a) {
  std::vector<double> area(a.positions.size() / 3, 0.0);
  for (int64_t f = 0; f < a.num_triangles(); ++f) {
    const int32_t* t = &a.triangles[3 * size_t(f)];
    const double* p = &a.positions[3 * size_t(t[0])];
    const double* q = &a.positions[3 * size_t(t[1])];
    const double* r = &a.positions[3 * size_t(t[2])];
    const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double c[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double triangle = 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    for (int j = 0; j < 3; ++j) area[t[j]] += triangle / 3.0;
  }
  return area;
}

void check_areas(const Mesh& mesh, const topstoc_test::Arrays& a) {
  const auto expected = areas_by_hand(a);
  const auto& areas = mesh.vertex_areas();
  REQUIRE(int64_t(areas.size()) == int64_t(expected.size()));
  double sum = 0.0;
  for (size_t v = 0; v < expected.size(); ++v) {
    CHECK(areas[mesh.vertex_index()[v]] == doctest::Approx(expected[v]).epsilon(1e-12));
    sum += expected[v];
  }
  CHECK(mesh.mean_vertex_area() == doctest::Approx(sum / double(expected.size())).epsilon(1e-12));
}

}  // namespace

TEST_CASE("vertex areas are a third of the area of each vertex's triangles") {
  SUBCASE("a planar grid of unit squares") {
    const auto a = topstoc_test::grid(5, 3);
    const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
    check_areas(mesh, a);
    // triangles of area 1/2, the quads split from (0, 0) towards (5, 3): corner (0, 3) is in
    // one, corner (0, 0) in two, the inner vertex (1, 1) in six
    CHECK(mesh.vertex_areas()[mesh.vertex_index()[3]] == doctest::Approx(0.5 / 3.0));
    CHECK(mesh.vertex_areas()[mesh.vertex_index()[0]] == doctest::Approx(2 * 0.5 / 3.0));
    CHECK(mesh.vertex_areas()[mesh.vertex_index()[5]] == doctest::Approx(6 * 0.5 / 3.0));
  }
  SUBCASE("a torus") {
    const auto a = topstoc_test::torus(30, 12);
    const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
    check_areas(mesh, a);
  }
}

TEST_CASE("vertex areas asked for by two threads at once are built once, the same for both") {
  const auto a = topstoc_test::torus(200, 100);  // 20,000 vertices: the build runs on the team
  const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  const void* seen[2] = {nullptr, nullptr};
  double means[2] = {0, 0};
  std::thread other([&] {
    seen[1] = &mesh.vertex_areas();
    means[1] = mesh.mean_vertex_area();
  });
  seen[0] = &mesh.vertex_areas();
  means[0] = mesh.mean_vertex_area();
  other.join();
  CHECK(seen[0] == seen[1]);
  CHECK(means[0] == means[1]);
  check_areas(mesh, a);
}
