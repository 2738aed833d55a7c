// A vertex's faces are walked from the adjacency and the runs of faces sorted by their lowest
// vertex (Mesh::for_each_face) instead of kept in a table: compared with every face that holds
// the vertex, in increasing order, found by a scan of all faces, on meshes with borders,
// isolated vertices, dropped duplicates and degenerates, non-manifold edges and a pinched vertex.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

namespace {

using topstoc_test::Arrays;

// Each vertex's faces by a scan of every face, in increasing order.
std::vector<std::vector<int32_t>> faces_by_scan(const topstoc::Mesh& mesh) {
  std::vector<std::vector<int32_t>> around(mesh.num_vertices());
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) around[mesh.faces()[3 * size_t(f) + c]].push_back(f);
  return around;
}

topstoc::MeshReport check_faces_around(const Arrays& a) {
  const topstoc::Mesh mesh(a.positions, a.triangles.data(), int64_t(a.triangles.size() / 3));
  const auto expected = faces_by_scan(mesh);
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    std::vector<int32_t> walked;
    mesh.for_each_face(v, [&](int32_t f) { walked.push_back(f); });
    CHECK(walked == expected[v]);
    CHECK(mesh.face_count(v) == int32_t(expected[v].size()));
    CHECK(mesh.first_face(v) == (expected[v].empty() ? -1 : expected[v][0]));
    CHECK(mesh.in_faces(v) == !expected[v].empty());
  }
  // The table, made again on first use, holds the same lists.
  const auto& offsets = mesh.vertex_face_offsets();
  const auto& table = mesh.vertex_faces();
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    CHECK(std::vector<int32_t>(table.begin() + offsets[v], table.begin() + offsets[v + 1]) == expected[v]);
  return mesh.report();
}

}  // namespace

TEST_CASE("a vertex's faces walked from the adjacency are the faces holding it, in order") {
  check_faces_around(topstoc_test::torus(40, 30));
  check_faces_around(topstoc_test::grid(17, 9));  // borders
  check_faces_around(topstoc_test::octahedron());
}

TEST_CASE("a vertex's faces after dropped triangles, on non-manifold and pinched meshes") {
  Arrays a = topstoc_test::grid(6, 5);
  const int32_t n = int32_t(a.positions.size() / 3);
  // Two isolated vertices, a degenerate triangle, duplicates in both orientations, a third
  // triangle on an edge (non-manifold) and a second fan at a vertex (pinched).
  for (int i = 0; i < 3; ++i) a.positions.push_back(9.0 + i);
  for (int i = 0; i < 3; ++i) a.positions.push_back(-9.0 - i);
  for (int i = 0; i < 9; ++i) a.positions.push_back(0.37 * i + 3.0);
  const int32_t x = n + 2, y = n + 3, z = n + 4;
  const std::vector<int32_t> extra = {a.triangles[0], a.triangles[0], a.triangles[1],
                                      a.triangles[2], a.triangles[1], a.triangles[0],
                                      a.triangles[3], a.triangles[4], a.triangles[5],
                                      a.triangles[0], a.triangles[2], x,
                                      n - 1, y, z};
  a.triangles.insert(a.triangles.begin() + 6, extra.begin(), extra.end());
  const topstoc::MeshReport report = check_faces_around(a);
  CHECK(report.isolated_vertices == 2);
  CHECK(report.degenerate_triangles == 1);
  CHECK(report.duplicate_triangles == 2);
  CHECK(report.nonmanifold_edges == 1);
  CHECK(report.nonmanifold_vertices == 1);
}
