// The feature layout's per-vertex and per-edge tables are left empty on a closed manifold mesh
// without feature edges (docs/bench_notes/scale-memory.md), and its accessors then give what
// the tables would hold: checked against counts made here from the caller's arrays, and the
// tables kept wherever a vertex has more than one sector or an edge is a feature. Also the
// mesh's first corner of each vertex, looked up where read, against a scan of the triangles.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/features.hpp"

using topstoc::Mesh;

namespace {

std::shared_ptr<const topstoc::FeatureLayout> plain_layout(const Mesh& mesh) {
  return topstoc::build_feature_layout(mesh, nullptr, 0, nullptr, 0, 0.0);
}

Mesh make(const topstoc_test::Arrays& a) { return Mesh(a.positions, a.triangles.data(), a.num_triangles()); }

// Two octahedra sharing one vertex (the first's -z pole is the second's +z pole): closed, no
// feature edge, one pinched vertex with two sectors.
topstoc_test::Arrays pinched_octahedra() {
  topstoc_test::Arrays a = topstoc_test::octahedron();
  const topstoc_test::Arrays b = topstoc_test::octahedron();
  for (int32_t v = 1; v < 6; ++v)  // the second's vertices 1..5 below the shared pole (0, 0, -1)
    a.positions.insert(a.positions.end(), {b.positions[3 * v], b.positions[3 * v + 1], b.positions[3 * v + 2] - 2.0});
  for (int32_t c : b.triangles) a.triangles.push_back(c == 0 ? 5 : c + 5);
  return a;
}

}  // namespace

TEST_CASE("a closed manifold mesh without features keeps no feature tables, and the accessors give them") {
  topstoc_test::Arrays a = topstoc_test::torus(12, 9);
  a.positions.insert(a.positions.end(), {9.0, 9.0, 9.0});  // an isolated vertex: no sector
  const Mesh mesh = make(a);
  const auto layout = plain_layout(mesh);
  CHECK(layout->sectors.empty());
  CHECK(layout->vertex_feature.empty());
  CHECK(layout->vertex_corner.empty());
  CHECK(layout->edge_feature.empty());
  CHECK(layout->feature_edges.empty());
  CHECK_FALSE(layout->has_feature_vertices);
  // In faces, per caller vertex, from the arrays.
  std::vector<int32_t> in_faces(a.positions.size() / 3, 0);
  for (int32_t c : a.triangles) in_faces[c] = 1;
  int64_t chi6 = 0;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    CHECK(layout->sectors_of(mesh, v) == in_faces[mesh.vertex_source()[v]]);
    CHECK_FALSE(layout->is_feature_vertex(v));
    CHECK_FALSE(layout->is_corner(v));
    chi6 += layout->chi_of(mesh, v);
  }
  for (int32_t e = 0; e < mesh.num_edges(); ++e) CHECK_FALSE(layout->is_feature_edge(e));
  CHECK(chi6 == 0);  // six times the torus's Euler characteristic
}

TEST_CASE("the feature tables are kept where a vertex has two sectors or an edge is a feature") {
  const Mesh pinched = make(pinched_octahedra());
  const auto layout = plain_layout(pinched);
  REQUIRE(layout->feature_edges.empty());
  REQUIRE(layout->sectors.size() == size_t(pinched.num_vertices()));
  const int32_t pole = pinched.vertex_index()[5];
  CHECK(layout->sectors_of(pinched, pole) == 2);
  CHECK(layout->is_corner(pole));
  int32_t corners = 0;
  for (int32_t v = 0; v < pinched.num_vertices(); ++v) corners += layout->is_corner(v);
  CHECK(corners == 1);

  const topstoc_test::Arrays g = topstoc_test::grid(4, 3);
  const Mesh grid = make(g);
  const auto bordered = plain_layout(grid);
  REQUIRE(bordered->edge_feature.size() == size_t(grid.num_edges()));
  int32_t border_vertices = 0;
  for (int32_t v = 0; v < grid.num_vertices(); ++v) border_vertices += bordered->is_feature_vertex(v);
  CHECK(border_vertices == 2 * (4 + 3));  // the rim of a 4 x 3 grid of quads
  CHECK(bordered->feature_edges.size() == size_t(2 * (4 + 3)));
}

TEST_CASE("a vertex's first corner is its corner in the first of its triangles the mesh keeps") {
  const topstoc_test::Arrays a = pinched_octahedra();
  const Mesh mesh = make(a);
  // The mesh's first face of a vertex is its lowest internal face id; face_source maps it back.
  std::vector<int32_t> first_face(mesh.num_vertices(), -1);
  for (int32_t f = mesh.num_faces() - 1; f >= 0; --f)
    for (int j = 0; j < 3; ++j) first_face[mesh.faces()[3 * size_t(f) + j]] = f;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
    const int32_t caller_triangle = mesh.face_source()[first_face[v]];
    int32_t slot = -1;
    for (int j = 0; j < 3; ++j)
      if (a.triangles[3 * size_t(caller_triangle) + j] == mesh.vertex_source()[v]) slot = j;
    REQUIRE(slot >= 0);
    CHECK(mesh.first_corner(v) == 3 * caller_triangle + slot);
  }
}

// Bends (curve_bends.hpp), against what the grid's border is by construction: a rectangle
// turns by 90 degrees at its four corners and nowhere else; pushed into a saw-tooth whose
// teeth turn by 90 degrees every third vertex, at every tip and every notch (and by 45 at
// its ends); into a zigzag of one vertex in two (it turns by 44 degrees at every vertex, but
// not over two edges), at none but the corners.
TEST_CASE("a border's bends are its sharp turns over one and two edges, sharpest first") {
  const int32_t n = 12, m = 9;
  topstoc_test::Arrays a = topstoc_test::grid(n, m);
  auto at = [&](int32_t i, int32_t j) { return i * (m + 1) + j; };  // vertex (i, j) of the grid
  auto bends_of = [](const topstoc_test::Arrays& arrays) {
    const Mesh mesh = make(arrays);
    const auto layout = plain_layout(mesh);
    std::vector<int32_t> callers;
    for (int32_t v : layout->curve_bends) callers.push_back(mesh.vertex_source()[v]);
    std::sort(callers.begin(), callers.end());
    return callers;
  };
  CHECK(bends_of(a) == std::vector<int32_t>{at(0, 0), at(0, m), at(n, 0), at(n, m)});
  topstoc_test::Arrays zigzag = a, saw = a;
  std::vector<int32_t> tips;
  for (int32_t j = 1; j < m; ++j) zigzag.positions[3 * at(0, j)] -= (j % 2) * 0.4;  // along the i = 0 side
  for (int32_t i = 0; i <= n; ++i) {  // along the j = 0 side: teeth of height 1 every 6 vertices
    saw.positions[3 * at(i, 0) + 1] -= std::min(i % 6, 6 - i % 6);
    if (i % 3 == 0) tips.push_back(at(i, 0));
  }
  CHECK(bends_of(zigzag) == std::vector<int32_t>{at(0, 0), at(0, m), at(n, 0), at(n, m)});
  // The saw's ends (0, 0) and (n, 0) are tips or notches too; (0, m) and (n, m) stay corners.
  tips.push_back(at(0, m)), tips.push_back(at(n, m));
  std::sort(tips.begin(), tips.end());
  CHECK(bends_of(saw) == tips);
  // Sharpest first: the saw's two ends, which turn by 45 degrees, come last.
  const Mesh mesh = make(saw);
  const auto layout = plain_layout(mesh);
  const auto& bends = layout->curve_bends;
  REQUIRE(bends.size() == tips.size());
  std::vector<int32_t> last{mesh.vertex_source()[bends[bends.size() - 2]], mesh.vertex_source()[bends.back()]};
  std::sort(last.begin(), last.end());
  CHECK(last == std::vector<int32_t>{at(0, 0), at(n, 0)});
}
