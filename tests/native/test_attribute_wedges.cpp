// The wedges of each cluster (attribute_wedges.hpp) on a grid cut by a UV seam along x = 2: the
// corners at a seam vertex fall in two wedges by the side of the seam their triangle lies on
// (read from the geometry here, not from the values), every other vertex has one.
#include <doctest/doctest.h>

#include <vector>

#include "decimate/attribute_wedges.hpp"
#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

using topstoc::CornerAttributes;
using topstoc::Mesh;

namespace {

struct SeamedGrid {
  topstoc_test::Arrays arrays = topstoc_test::grid(4, 3);
  std::vector<double> values;  // per caller corner: u = x, plus 10 right of the seam
  Mesh mesh{arrays.positions, arrays.triangles.data(), arrays.num_triangles()};

  SeamedGrid() {
    for (int64_t t = 0; t < arrays.num_triangles(); ++t)
      for (int j = 0; j < 3; ++j) {
        const double x = arrays.positions[3 * size_t(arrays.triangles[3 * t + j])];
        values.push_back(x + (right_of_seam(int32_t(t)) ? 10.0 : 0.0));
      }
  }
  bool right_of_seam(int32_t caller_face) const {
    double x = 0;
    for (int j = 0; j < 3; ++j) x += arrays.positions[3 * size_t(arrays.triangles[3 * size_t(caller_face) + j])];
    return x / 3 > 2.0;
  }
  CornerAttributes attributes() const { return {values.data(), 1, nullptr}; }
};

}  // namespace

TEST_CASE("a seam vertex has a wedge per side, other vertices one") {
  SeamedGrid g;
  const Mesh& mesh = g.mesh;
  std::vector<int32_t> label(mesh.num_vertices());
  for (int32_t v = 0; v < mesh.num_vertices(); ++v) label[v] = v;  // each vertex its own cluster
  const auto wedge = topstoc::corner_wedges(mesh, g.attributes(), label, mesh.num_vertices(), 4);
  const auto& faces = mesh.faces();
  for (int32_t c = 0; c < 3 * mesh.num_faces(); ++c)
    for (int32_t d = 0; d < c; ++d) {
      if (faces[c] != faces[d]) continue;
      const bool on_seam = mesh.position(faces[c])[0] == 2.0;
      const bool same_side = g.right_of_seam(mesh.face_source()[c / 3]) == g.right_of_seam(mesh.face_source()[d / 3]);
      CHECK((wedge[c] == wedge[d]) == (!on_seam || same_side));
    }
}

TEST_CASE("a cluster across the seam keeps its two sides as two wedges") {
  SeamedGrid g;
  const Mesh& mesh = g.mesh;
  const std::vector<int32_t> label(mesh.num_vertices(), 0);  // one cluster
  const auto wedge = topstoc::corner_wedges(mesh, g.attributes(), label, 1, 4);
  for (int32_t c = 0; c < 3 * mesh.num_faces(); ++c) {
    CHECK(wedge[c] < 2);
    const bool same_side = g.right_of_seam(mesh.face_source()[c / 3]) == g.right_of_seam(mesh.face_source()[0]);
    CHECK((wedge[c] == wedge[0]) == same_side);
  }
}
