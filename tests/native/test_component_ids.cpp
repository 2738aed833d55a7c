// Each vertex's component is held in the fewest bytes its ids need (ComponentIds): compared with
// components found by a search over the faces (numbered in order of their lowest vertex, -1 for
// an isolated vertex) on meshes of 1, 100, 300 and 40,000 components, with and without isolated
// vertices, and the widths those counts give. The manifold flags (VertexFlags) are held only
// where a vertex is not manifold.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

namespace {

using topstoc_test::Arrays;

// `count` copies of an octahedron side by side, then `isolated` vertices in no face.
Arrays octahedra(int32_t count, int32_t isolated) {
  const Arrays one = topstoc_test::octahedron();
  const int32_t n = int32_t(one.positions.size() / 3);
  Arrays out;
  for (int32_t i = 0; i < count; ++i) {
    for (size_t k = 0; k < one.positions.size(); ++k) out.positions.push_back(one.positions[k] + (k % 3 == 0 ? 3.0 * i : 0.0));
    for (const int32_t v : one.triangles) out.triangles.push_back(v + i * n);
  }
  for (int32_t i = 0; i < isolated; ++i) out.positions.insert(out.positions.end(), {-5.0 - i, 1.0, 2.0});
  return out;
}

// Components by a search over the faces, numbered in order of their lowest vertex.
std::vector<int32_t> components_by_search(const topstoc::Mesh& mesh) {
  const int32_t n = mesh.num_vertices();
  std::vector<std::vector<int32_t>> around(n);
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c)
      for (int d = 0; d < 3; ++d)
        if (c != d) around[mesh.faces()[3 * size_t(f) + c]].push_back(mesh.faces()[3 * size_t(f) + d]);
  std::vector<int32_t> component(n, -1);
  int32_t next = 0;
  for (int32_t v = 0; v < n; ++v) {
    if (component[v] >= 0 || around[v].empty()) continue;
    std::vector<int32_t> stack{v};
    component[v] = next;
    while (!stack.empty()) {
      const int32_t x = stack.back();
      stack.pop_back();
      for (const int32_t y : around[x])
        if (component[y] < 0) component[y] = next, stack.push_back(y);
    }
    ++next;
  }
  return component;
}

void check_components(const Arrays& a, int expected_width) {
  const topstoc::Mesh mesh(a.positions, a.triangles.data(), a.num_triangles());
  const auto expected = components_by_search(mesh);
  REQUIRE(mesh.component().size() == expected.size());
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) CHECK(mesh.component()[v] == expected[v]);
  CHECK(mesh.component().width() == expected_width);
}

}  // namespace

TEST_CASE("component ids: one component without isolated vertices takes no bytes") {
  check_components(topstoc_test::torus(12, 9), 0);
  check_components(octahedra(1, 0), 0);
}

TEST_CASE("component ids: the width follows the count and isolated vertices") {
  check_components(octahedra(1, 2), 1);  // -1 needs a byte
  check_components(octahedra(100, 1), 1);
  check_components(octahedra(300, 0), 2);
  check_components(octahedra(40000, 3), 4);
}

TEST_CASE("component ids: every width holds -1 and its largest id") {
  for (const int32_t components : {1, 126, 127, 32766, 32767, 100000}) {
    topstoc::Buffer<int32_t> ids(5);
    const int32_t values[5] = {-1, 0, components - 1, components / 2, -1};
    for (int i = 0; i < 5; ++i) ids[i] = values[i];
    topstoc::ComponentIds packed;
    packed.assign(ids, components);
    for (int i = 0; i < 5; ++i) CHECK(packed[i] == values[i]);
  }
}

TEST_CASE("manifold flags: none held when every vertex is manifold, else each vertex's") {
  const Arrays torus = topstoc_test::torus(12, 9);
  const topstoc::Mesh closed(torus.positions, torus.triangles.data(), torus.num_triangles());
  CHECK(!closed.manifold_vertex().held());
  CHECK(closed.manifold_vertex().size() == size_t(closed.num_vertices()));
  for (int32_t v = 0; v < closed.num_vertices(); ++v) CHECK(closed.manifold_vertex()[v] == 1);
  // Two octahedra sharing a vertex: it is pinched (two fans), the others manifold.
  Arrays pinched = octahedra(2, 0);
  for (int32_t& v : pinched.triangles)
    if (v == 6 + 3) v = 1;  // the second one's vertex (-1, 0, 0) + 3 = (2, 0, 0) becomes the first's (1, 0, 0)
  const topstoc::Mesh mesh(pinched.positions, pinched.triangles.data(), pinched.num_triangles());
  CHECK(mesh.manifold_vertex().held());
  int32_t nonmanifold = 0;
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) nonmanifold += mesh.manifold_vertex()[v] == 0;
  CHECK(nonmanifold == 1);
  CHECK(mesh.manifold_vertex()[mesh.vertex_index()[1]] == 0);
}
