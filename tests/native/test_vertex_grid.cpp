// The vertex grid's nearest vertex against a brute-force scan, for points near the surface, far
// outside it (the search falls back to every vertex) and on ties (the lowest id wins).
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "distance/vertex_grid.hpp"

using topstoc::Surface;
using topstoc::VertexGrid;

namespace {

Surface scattered_triangles(std::mt19937& random, int32_t count) {
  std::uniform_real_distribution<double> coordinate(-3.0, 3.0), offset(-0.2, 0.2);
  std::vector<double> positions;
  for (int32_t t = 0; t < count; ++t) {
    const double centre[3] = {coordinate(random), coordinate(random), 0.1 * coordinate(random)};
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) positions.push_back(centre[k] + offset(random));
  }
  positions.insert(positions.end(), {50.0, 50.0, 50.0});  // a vertex no triangle uses: never an answer
  std::vector<int32_t> triangles(3 * size_t(count));
  for (int32_t i = 0; i < 3 * count; ++i) triangles[size_t(i)] = i;
  return Surface(std::move(positions), std::move(triangles));
}

}  // namespace

TEST_CASE("vertex grid: the nearest vertex equals the brute-force nearest used vertex, near and far") {
  std::mt19937 random(23);
  const Surface surface = scattered_triangles(random, 300);
  for (double cell : {0.05, 0.4, 3.0}) {
    const VertexGrid grid(surface, cell);
    std::uniform_real_distribution<double> near(-3.5, 3.5), far(-200.0, 200.0);
    for (int probe = 0; probe < 400; ++probe) {
      const bool outside = probe % 4 == 0;
      const double p[3] = {outside ? far(random) : near(random), outside ? far(random) : near(random),
                           outside ? far(random) : 0.3 * near(random)};
      double best = 1e300;
      int32_t best_vertex = -1;
      for (int32_t v = 0; v < surface.num_vertices(); ++v) {
        if (!surface.used()[size_t(v)]) continue;
        const double* q = &surface.positions()[3 * size_t(v)];
        const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
        if (d2 < best) best = d2, best_vertex = v;
      }
      const VertexGrid::Nearest hit = grid.nearest(p);
      CHECK(hit.distance2 == best);
      CHECK(hit.vertex == best_vertex);
      std::vector<int32_t> seen;  // every vertex within a radius is visited
      const double radius = 0.7;
      grid.for_each_near(p, radius, [&](int32_t v) { seen.push_back(v); });
      for (int32_t v = 0; v < surface.num_vertices(); ++v) {
        const double* q = &surface.positions()[3 * size_t(v)];
        const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
        if (surface.used()[size_t(v)] && d2 <= radius * radius)
          CHECK(std::find(seen.begin(), seen.end(), v) != seen.end());
      }
    }
  }
}

TEST_CASE("vertex grid: a tie goes to the lowest vertex id, and one point in many copies is found") {
  std::vector<double> positions;
  for (int i = 0; i < 6; ++i) positions.insert(positions.end(), {1.0, 2.0, 3.0});  // two triangles on one point
  const Surface surface(positions, {0, 1, 2, 3, 4, 5});
  const VertexGrid grid(surface, 0.5);
  const double p[3] = {1.0, 2.0, 4.0};
  const VertexGrid::Nearest hit = grid.nearest(p);
  CHECK(hit.vertex == 0);
  CHECK(hit.distance2 == 1.0);
}
