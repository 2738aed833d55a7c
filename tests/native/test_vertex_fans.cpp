// A vertex's fans (and the sheets, sectors and edge tables behind them) are read from the
// vertex's own faces: compared with a scan of every face on meshes with borders, a non-manifold
// edge, a pinched vertex and creases blocked as features.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/fans.hpp"
#include "core/union_find.hpp"
#include "decimate/pinched_fans.hpp"
#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/features.hpp"

namespace {

using topstoc::Mesh;
using topstoc_test::Arrays;

bool holds(const Mesh& mesh, int32_t f, int32_t v) {
  const int32_t* t = &mesh.faces()[3 * size_t(f)];
  return t[0] == v || t[1] == v || t[2] == v;
}

// The faces holding both a and b, by a scan of every face.
std::vector<int32_t> faces_of_edge(const Mesh& mesh, int32_t a, int32_t b) {
  std::vector<int32_t> out;
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    if (holds(mesh, f, a) && holds(mesh, f, b)) out.push_back(f);
  return out;
}

// Fans by the definition: v's faces (in increasing order) joined across an edge at v that
// exactly two faces hold and `blocked` does not name, numbered by first appearance.
template <class Blocked>
std::vector<int32_t> fans_by_scan(const Mesh& mesh, int32_t v, Blocked blocked) {
  std::vector<int32_t> around;
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    if (holds(mesh, f, v)) around.push_back(f);
  topstoc::UnionFind joined(int32_t(around.size()));
  for (size_t i = 0; i < around.size(); ++i)
    for (size_t j = i + 1; j < around.size(); ++j)
      for (int c = 0; c < 3; ++c) {
        const int32_t w = mesh.faces()[3 * size_t(around[i]) + c];
        if (w == v || !holds(mesh, around[j], w)) continue;
        if (faces_of_edge(mesh, v, w).size() == 2 && !blocked(mesh.find_edge(v, w))) joined.unite(int32_t(i), int32_t(j));
      }
  std::vector<int32_t> fan(around.size()), number(around.size(), -1);
  int32_t fans = 0;
  for (size_t i = 0; i < around.size(); ++i) {
    const int32_t root = joined.find(int32_t(i));
    if (number[root] < 0) number[root] = fans++;
    fan[i] = number[root];
  }
  return fan;
}

// A 6 x 5 grid (borders) with a third triangle on one edge (non-manifold), a second fan at a
// corner (pinched) and a hole.
Arrays defective_grid() {
  Arrays a = topstoc_test::grid(6, 5);
  const int32_t n = int32_t(a.positions.size() / 3);
  for (int i = 0; i < 9; ++i) a.positions.push_back(0.37 * i + 3.0);
  const int32_t x = n, y = n + 1, z = n + 2;
  a.triangles.erase(a.triangles.begin() + 30, a.triangles.begin() + 33);  // a hole
  const std::vector<int32_t> extra = {a.triangles[0], a.triangles[2], x, n - 1, y, z};
  a.triangles.insert(a.triangles.end(), extra.begin(), extra.end());
  return a;
}

void check_fans(const Arrays& a, double feature_angle) {
  const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  const auto layout = topstoc::build_feature_layout(mesh, nullptr, 0, nullptr, 0, feature_angle);
  auto feature = [&](int32_t e) { return layout->is_feature_edge(e); };
  auto none = [](int32_t) { return false; };
  std::vector<int32_t> fan_of_slot;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    const int32_t count = topstoc::vertex_fans(mesh, v, none, fan_of_slot);
    const auto expected = fans_by_scan(mesh, v, none);
    CHECK(fan_of_slot == expected);
    CHECK(count == (expected.empty() ? 0 : *std::max_element(expected.begin(), expected.end()) + 1));
    // The sector of each face at v: its fan with the feature edges blocked.
    const auto sectors = fans_by_scan(mesh, v, feature);
    int32_t slot = 0;
    mesh.for_each_face(v, [&](int32_t f) { CHECK(layout->sector_of(mesh, v, f) == sectors[slot++]); });
    CHECK(layout->sectors_of(mesh, v) == (sectors.empty() ? 0 : *std::max_element(sectors.begin(), sectors.end()) + 1));
  }
  // The edge tables, built apart: each edge's faces and each face side's edge.
  for (int32_t e = 0; e < mesh.num_edges(); ++e) {
    const int32_t a0 = mesh.edge_vertices()[2 * size_t(e)], b0 = mesh.edge_vertices()[2 * size_t(e) + 1];
    const auto expected = faces_of_edge(mesh, a0, b0);
    std::vector<int32_t> walked;
    mesh.for_each_edge_face(e, [&](int32_t f) { walked.push_back(f); });
    CHECK(walked == expected);
    CHECK(mesh.edge_face_count(e) == int32_t(expected.size()));
  }
  for (int32_t e = 0; e < mesh.num_edges(); ++e) {
    const auto& efo = mesh.edge_face_offsets();
    const std::vector<int32_t> table(mesh.edge_faces().begin() + efo[e], mesh.edge_faces().begin() + efo[e + 1]);
    CHECK(table == faces_of_edge(mesh, mesh.edge_vertices()[2 * size_t(e)], mesh.edge_vertices()[2 * size_t(e) + 1]));
  }
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int32_t* t = &mesh.faces()[3 * size_t(f)];
      CHECK(mesh.face_edges()[3 * size_t(f) + c] == mesh.find_edge(t[c], t[(c + 1) % 3]));
    }
}

}  // namespace

TEST_CASE("a vertex's fans and sectors from its own faces are those of a scan of every face") {
  check_fans(topstoc_test::torus(12, 9), 0.0);
  check_fans(topstoc_test::torus(12, 9), 0.3);  // creases: two sectors and more
  check_fans(topstoc_test::grid(7, 4), 0.0);
  check_fans(defective_grid(), 0.0);
  check_fans(defective_grid(), 0.2);
}

TEST_CASE("sheets join faces across edges of exactly two faces, as a scan of every edge does") {
  const Arrays a = defective_grid();
  const Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  REQUIRE(mesh.report().nonmanifold_edges == 1);
  REQUIRE(mesh.report().nonmanifold_vertices >= 1);
  topstoc::UnionFind expected(mesh.num_faces());
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    for (int32_t w = v + 1; w < mesh.num_vertices(); ++w) {
      const auto faces = faces_of_edge(mesh, v, w);
      if (faces.size() == 2) expected.unite(faces[0], faces[1]);
    }
  const std::vector<int32_t> sheet = topstoc::face_sheets(mesh);
  for (int32_t f = 0; f < mesh.num_faces(); ++f) CHECK(sheet[f] == expected.find(f));
}
