// The bound through the triangles beneath a piece (distance/projected_bound.hpp) against the
// distances of a dense sampling of the piece, measured by the BVH's exact closest points; and
// the max's bracket it makes cheap where a coarse surface runs over a fine one.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "sampled_distance.hpp"
#include "distance/bounded_max.hpp"
#include "distance/projected_bound.hpp"
#include "distance/triangle_walk.hpp"
#include "distance/vertex_stars.hpp"

using topstoc::BeneathScratch;
using topstoc::projected_bound;
using topstoc::Surface;

namespace {

// An n x n grid of squares over [0, 1]^2, two triangles each, facing +z, at height z(x, y).
// `skip` (a square's index, or -1) leaves a hole; `flip` turns that square's first triangle over.
template <class Height>
Surface grid(int n, Height z, int skip = -1, int flip = -1) {
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = double(i) / n, y = double(j) / n;
      positions.insert(positions.end(), {x, y, z(x, y)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1, square = j * n + i;
      if (square == skip) continue;
      if (square == flip) {
        triangles.insert(triangles.end(), {a, d, b});
      } else {
        triangles.insert(triangles.end(), {a, b, d});
      }
      triangles.insert(triangles.end(), {a, d, c});
    }
  return Surface(std::move(positions), std::move(triangles));
}

const double kInfinity = std::numeric_limits<double>::infinity();

// A random piece over the middle of the unit square, about 0.02 to 0.17 across (by round), tilted.
void random_piece(std::mt19937& random, int round, double p[3][3]) {
  std::uniform_real_distribution<double> along(0.1, 0.9), height(-0.05, 0.05), tilt(-1.0, 1.0);
  const double size = 0.02 + 0.15 * (round % 10) / 10.0;
  const double cx = along(random), cy = along(random), cz = height(random);
  for (int j = 0; j < 3; ++j) {
    const double angle = 2.0944 * j + tilt(random) * 0.3;
    p[j][0] = cx + size * std::cos(angle), p[j][1] = cy + size * std::sin(angle);
    p[j][2] = cz + 0.5 * size * tilt(random);
  }
}

}  // namespace

TEST_CASE("over a flat grid the bound is the piece's height, along its own normal when tilted") {
  const Surface flat = grid(20, [](double, double) { return 0.0; });
  BeneathScratch scratch;
  const double level[3][3] = {{0.2, 0.3, 0.02}, {0.7, 0.35, 0.02}, {0.4, 0.8, 0.02}};
  CHECK(projected_bound(level, flat, 1.0, 1000, scratch) == doctest::Approx(0.02).epsilon(1e-12));
  // tilted: the heights are measured along the piece's normal, a little longer than straight down
  const double p[3][3] = {{0.2, 0.3, 0.01}, {0.7, 0.35, 0.03}, {0.4, 0.8, 0.02}};
  const double bound = projected_bound(p, flat, 1.0, 1000, scratch);
  CHECK(bound >= sampled_max(p, flat));
  CHECK(bound <= 1.001 * 0.03);
  // a limit under it, or fewer candidates allowed than lie near it: no bound
  CHECK(projected_bound(p, flat, 0.02, 1000, scratch) == kInfinity);
  CHECK(projected_bound(p, flat, 1.0, 10, scratch) == kInfinity);
}

TEST_CASE("a hole, a triangle turned over or the grid's edge under the piece gives no bound") {
  BeneathScratch scratch;
  const double p[3][3] = {{0.2, 0.3, 0.01}, {0.7, 0.35, 0.03}, {0.4, 0.8, 0.02}};
  const auto zero = [](double, double) { return 0.0; };
  const int under = 10 * 20 + 9;  // the square at (0.45, 0.5)-(0.5, 0.55), inside the piece's shadow
  CHECK(projected_bound(p, grid(20, zero, under), 1.0, 1000, scratch) == kInfinity);
  CHECK(projected_bound(p, grid(20, zero, -1, under), 1.0, 1000, scratch) == kInfinity);
  const double beyond[3][3] = {{0.8, 0.3, 0.01}, {1.2, 0.35, 0.03}, {0.9, 0.8, 0.02}};
  CHECK(projected_bound(beyond, grid(20, zero), 1.0, 1000, scratch) == kInfinity);
  // a hole outside the shadow changes nothing
  CHECK(projected_bound(p, grid(20, zero, 0), 1.0, 1000, scratch) == projected_bound(p, grid(20, zero), 1.0, 1000, scratch));
}

TEST_CASE("along a crease: a side on the grid's edge and a face folded back over the piece") {
  // The grid plus a face rising from its edge x = 1 back over it (to x = 0.6 at height 0.3),
  // facing up: a piece on the grid with a side on that edge lies on the surface (max 0). The
  // plain bound fails it twice (the edge is a boundary touching the piece, and the folded face
  // is higher than the limit over it); along_creases leaves the folded face out and allows the
  // boundary along the piece's side, adding only the margin's reach. A piece reaching past the
  // edge still gets no bound (its points there are off the surface).
  const Surface flat = grid(20, [](double, double) { return 0.0; });
  std::vector<double> positions = flat.positions();
  std::vector<int32_t> triangles = flat.triangles();
  const int32_t base = flat.num_vertices();
  positions.insert(positions.end(), {1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.6, 0.0, 0.3, 0.6, 1.0, 0.3});
  triangles.insert(triangles.end(), {base, base + 1, base + 2, base + 2, base + 1, base + 3});
  const Surface folded(std::move(positions), std::move(triangles));
  BeneathScratch scratch;
  const double on[3][3] = {{0.8, 0.3, 0.0}, {1.0, 0.35, 0.0}, {1.0, 0.7, 0.0}};
  CHECK(projected_bound(on, folded, 0.1, 1000, scratch) == kInfinity);
  CHECK(projected_bound(on, flat, 0.1, 1000, scratch) == kInfinity);
  for (const Surface* to : {&flat, &folded}) {
    const double bound = projected_bound(on, *to, 0.1, 1000, scratch, true);
    CHECK(bound >= 0.0);
    CHECK(bound <= 1e-8);
  }
  const double raised[3][3] = {{0.8, 0.3, 0.02}, {1.0, 0.35, 0.02}, {1.0, 0.7, 0.02}};
  const double bound = projected_bound(raised, folded, 0.1, 1000, scratch, true);
  CHECK(bound >= sampled_max(raised, folded) * (1 - 1e-12));
  CHECK(bound <= 0.02 * (1 + 1e-6));
  const double past[3][3] = {{0.8, 0.3, 0.0}, {1.01, 0.35, 0.0}, {1.01, 0.7, 0.0}};
  CHECK(sampled_max(past, folded) > 0.0);
  CHECK(projected_bound(past, folded, 0.1, 1000, scratch, true) == kInfinity);
}

TEST_CASE("over a bumpy grid the bound is never under a dense sampling's distances") {
  const Surface bumpy = grid(30, [](double x, double y) { return 0.03 * std::sin(9 * x) * std::cos(7 * y); });
  std::mt19937 random(5);
  BeneathScratch scratch;
  int bounded = 0;
  for (int round = 0; round < 100; ++round) {
    double p[3][3];
    random_piece(random, round, p);
    const double bound = projected_bound(p, bumpy, 0.3, 1000, scratch);
    if (bound == kInfinity) continue;
    ++bounded;
    CHECK(bound >= sampled_max(p, bumpy) * (1 - 1e-12));
  }
  CHECK(bounded >= 50);  // not vacuous: most pieces (73 of 100) lie wholly over the grid
}

TEST_CASE("the chain grown from the corners' triangles bounds what the tree's candidates bound, never under a sampling") {
  // The same pieces over the bumpy grid, along creases, from their corners' nearest triangles
  // (projected_bound_around) and from the tree's (projected_bound): every bound holds against a
  // dense sampling, and the grown chain settles whatever the tree's does (it looks at fewer).
  // On the grid with a hole under some pieces, neither settles those.
  const auto bumps = [](double x, double y) { return 0.03 * std::sin(9 * x) * std::cos(7 * y); };
  for (const int hole : {-1, 15 * 30 + 15}) {
    const Surface bumpy = grid(30, bumps, hole);
    const topstoc::Stars stars(bumpy);
    const topstoc::TriangleWalk walk(bumpy, stars);
    std::mt19937 random(9);
    BeneathScratch scratch;
    int settled = 0, fewer = 0;
    for (int round = 0; round < 200; ++round) {
      double p[3][3];
      random_piece(random, round, p);
      int32_t near[4] = {-1, -1, -1, -1};
      for (int j = 0; j < 3; ++j) near[j] = bumpy.bvh().closest(p[j]).triangle;
      const double boxed = projected_bound(p, bumpy, 0.3, 1000, scratch, true);
      const size_t looked_at_boxed = scratch.slots.size();
      const double grown = topstoc::projected_bound_around(p, bumpy, walk, near, 4, 0.3, 1000, scratch);
      fewer += scratch.slots.size() < looked_at_boxed;
      if (grown == kInfinity) {
        CHECK(boxed == kInfinity);
        continue;
      }
      ++settled;
      CHECK(grown >= sampled_max(p, bumpy) * (1 - 1e-12));
      CHECK(grown <= boxed);
    }
    CHECK(settled >= 80);
    CHECK(fewer >= settled / 2);
  }
}

TEST_CASE("the max's bracket of a coarse surface over a fine one settles in few queries") {
  // Two triangles over a 100 x 100 grid, 0.01 to 0.015 above it: the corner bounds alone split
  // them until their pieces are smaller than the slack between the distances and the max
  // (26,316 queries without the bound beneath; 5,022 with it).
  const Surface fine = grid(100, [](double, double) { return 0.0; });
  const Surface coarse({0.05, 0.05, 0.01, 0.95, 0.05, 0.015, 0.05, 0.95, 0.01, 0.95, 0.95, 0.015}, {0, 1, 3, 0, 3, 2});
  const topstoc::MaxBracket bracket = topstoc::bound_max_distance_by_tree(coarse, fine, 1e-2, 4000000);
  CHECK(bracket.converged);
  CHECK(bracket.lower <= 0.015 * (1 + 1e-12));
  CHECK(bracket.upper >= 0.015 * (1 - 1e-12));
  CHECK(bracket.upper <= 0.015 * 1.01 * (1 + 1e-12));
  CHECK(bracket.queries < 10000);
}

TEST_CASE("a fine surface under a coarse one settles its small triangles without measuring them") {
  // A flat 100 x 100 grid under an 8 x 8 grid of squares 0.01 to 0.014 above it: a leaf's
  // triangle spans less than one coarse triangle and is settled by the bound beneath it
  // (15,902 queries without it; 11,422 with it). The bracket holds against a dense sampling.
  const Surface fine = grid(100, [](double, double) { return 0.0; });
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  const int m = 8;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= m; ++i)
      positions.insert(positions.end(), {-0.05 + 1.1 * i / m, -0.05 + 1.1 * j / m, 0.01 + 0.001 * ((i * 7 + j * 3) % 5)});
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const int32_t a = j * (m + 1) + i, b = a + 1, c = a + m + 1, d = c + 1;
      triangles.insert(triangles.end(), {a, b, d, a, d, c});
    }
  const Surface coarse(std::move(positions), std::move(triangles));
  const topstoc::MaxBracket bracket = topstoc::bound_max_distance_by_tree(fine, coarse, 1e-2, 4000000);
  CHECK(bracket.converged);
  CHECK(bracket.upper <= bracket.lower * 1.01 * (1 + 1e-12));
  double sampled = 0.0;
  for (int32_t f = 0; f < fine.num_triangles(); f += 7) {
    double p[3][3];
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) p[j][k] = fine.positions()[3 * size_t(fine.triangles()[3 * size_t(f) + j]) + k];
    sampled = std::max(sampled, sampled_max(p, coarse));
  }
  CHECK(bracket.upper >= sampled * (1 - 1e-12));
  CHECK(bracket.queries < 13000);
}
