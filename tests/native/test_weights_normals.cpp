// The preparation's weights take each vertex's normal from sums made a range of vertices at a
// time (each face's cross product once for its corners in the range); they must be the bits of
// thesis eq. 4.1 computed from normals(), which sums each vertex's faces one vertex at a time.
// Meshes above the weights' block and chunk sizes, so that ranges have faces below them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

namespace {

// A double cone: two apexes of `rim` neighbours each, read from outside the weights' ring of
// blocks by most of their neighbours (their normals are made once: the hub path).
topstoc_test::Arrays double_cone(int32_t rim) {
  topstoc_test::Arrays a;
  a.positions = {0.0, 0.0, -1.0};
  for (int32_t i = 0; i < rim; ++i) {
    const double t = 6.283185307179586 * i / rim;
    a.positions.insert(a.positions.end(), {std::cos(t), std::sin(t), 0.1 * std::sin(7 * t)});
  }
  a.positions.insert(a.positions.end(), {0.0, 0.0, 1.0});
  for (int32_t i = 0; i < rim; ++i) {
    const int32_t j = (i + 1) % rim;
    a.triangles.insert(a.triangles.end(), {0, j + 1, i + 1, rim + 1, i + 1, j + 1});
  }
  return a;
}

void check_weights(const topstoc_test::Arrays& a) {
  const topstoc::Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  const auto& normals = mesh.normals();
  const auto& ao = mesh.adjacency_offsets();
  int32_t differ = 0;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    const int32_t d = ao[v + 1] - ao[v];
    double expected = 0.0;
    if (d > 0) {
      double dots = 0.0;
      for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
        const double* nv = &normals[3 * size_t(v)];
        const double* nu = &normals[3 * size_t(mesh.adjacency()[i])];
        dots += nv[0] * nu[0] + nv[1] * nu[1] + nv[2] * nu[2];
      }
      expected = std::clamp((double(d) - dots) / (2.0 * double(d)), 0.0, 1.0);
    }
    differ += mesh.weights()[v] != expected;
  }
  CHECK(differ == 0);
}

}  // namespace

TEST_CASE("the weights are eq. 4.1 from normals() to the bit") {
  check_weights(topstoc_test::torus(300, 230, 2.0, 0.9));  // 69,000 vertices: several blocks
  check_weights(topstoc_test::grid(160, 130));             // borders
  check_weights(topstoc_test::octahedron());
  check_weights(double_cone(60000));  // apexes of 60,000 neighbours
}
