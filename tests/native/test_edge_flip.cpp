// Collapser::flip (edge_flip.cpp): the tiny result's last stage turns the diagonal of two
// triangles; it must keep the orientation and the corners' sources, undo exactly, and refuse
// boundary edges, feature edges and flips that would join two vertices already joined.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "decimate/collapser.hpp"

using topstoc::CollapseSetup;
using topstoc::Collapser;

namespace {

CollapseSetup plain_setup(const std::vector<double>& positions, size_t corners) {
  const int32_t n = int32_t(positions.size() / 3);
  CollapseSetup s;
  s.quadrics = topstoc::VertexQuadrics(n, 0);
  s.positions = positions;
  s.world = positions;
  s.weight.assign(n, 1.0);
  s.locked.assign(n, 0);
  s.curve.assign(n, -1);
  s.corner_sector.assign(corners, 0);
  s.bin.assign(n, 0);
  s.quota = {0};
  return s;
}

// A unit square a(0) b(1) c(2) d(3) cut along a-b: f = (a, b, c), g = (b, a, d), both facing -z.
const std::vector<double> kSquare = {0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 0};
const std::vector<int32_t> kSquareTriangles = {0, 1, 2, 1, 0, 3};

}  // namespace

TEST_CASE("a flip turns the diagonal, keeps each vertex's corner source, and undoes exactly") {
  std::vector<int32_t> triangles = kSquareTriangles, corners = {10, 11, 12, 13, 14, 15};
  Collapser c(triangles, corners, plain_setup(kSquare, triangles.size()));
  Collapser::Flip saved;
  REQUIRE(c.flip(0, 0, saved));
  // (a, d, c) and (d, b, c): the same orientation; each corner copies its vertex's old corner
  CHECK(triangles == std::vector<int32_t>{0, 3, 2, 3, 1, 2});
  CHECK(corners == std::vector<int32_t>{10, 15, 12, 15, 13, 12});
  CHECK(c.live_faces() == 2);
  // The new edge d-c flips back to a-b (the vertices' triangle lists were kept in step).
  Collapser::Flip back;
  REQUIRE(c.flip(0, 1, back));
  int32_t with_a_and_b = 0;
  for (int t = 0; t < 2; ++t) {
    bool a = false, b = false;
    for (int j = 0; j < 3; ++j) a |= triangles[3 * t + j] == 0, b |= triangles[3 * t + j] == 1;
    with_a_and_b += a && b;
  }
  CHECK(with_a_and_b == 2);
  c.unflip(back);
  CHECK(triangles == std::vector<int32_t>{0, 3, 2, 3, 1, 2});
  c.unflip(saved);
  CHECK(triangles == kSquareTriangles);
  CHECK(corners == std::vector<int32_t>{10, 11, 12, 13, 14, 15});
}

TEST_CASE("no flip of a boundary edge, a feature edge, or where the new edge exists") {
  std::vector<int32_t> triangles = kSquareTriangles, corners = {0, 1, 2, 3, 4, 5};
  Collapser::Flip saved;
  {
    Collapser c(triangles, corners, plain_setup(kSquare, triangles.size()));
    CHECK_FALSE(c.flip(0, 1, saved));  // b-c has one triangle
    CHECK_FALSE(c.flip(0, 2, saved));  // c-a too
  }
  {
    auto setup = plain_setup(kSquare, triangles.size());
    setup.curve[0] = setup.curve[1] = 0;  // a-b runs along a feature curve
    Collapser c(triangles, corners, std::move(setup));
    CHECK_FALSE(c.flip(0, 0, saved));
  }
  CHECK(triangles == kSquareTriangles);
  // A tetrahedron: every pair of vertices is joined already.
  const std::vector<double> tet = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<int32_t> closed = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2}, closed_corners(12, 0);
  Collapser c(closed, closed_corners, plain_setup(tet, closed.size()));
  for (int32_t f = 0; f < 4; ++f)
    for (int32_t side = 0; side < 3; ++side) CHECK_FALSE(c.flip(f, side, saved));
}
