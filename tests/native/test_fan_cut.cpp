// The bound of a triangle over a vertex of a surface, sector by sector (distance/fan_cut.hpp),
// against the distances of a dense sampling of the triangle, measured by the BVH's exact closest
// points; and where it gives none.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "sampled_distance.hpp"
#include "distance/fan_cut.hpp"

using topstoc::fan_cut_bound;
using topstoc::shared_fan_cut_bound;
using topstoc::Stars;
using topstoc::Surface;

namespace {

const double kInfinity = std::numeric_limits<double>::infinity();

// A fan of n triangles around vertex 0 at the origin, facing +z; its rim at radius 1 with heights
// height(i). closed: the last triangle joins the rim back to its first vertex.
template <class Height>
Surface fan(int n, Height height, bool closed = true) {
  std::vector<double> positions = {0, 0, 0};
  std::vector<int32_t> triangles;
  for (int i = 0; i < n; ++i) {
    const double angle = 2 * 3.14159265358979 * i / n + 0.1 * std::sin(3.0 * i);
    positions.insert(positions.end(), {std::cos(angle), std::sin(angle), height(i)});
  }
  for (int i = 0; i < (closed ? n : n - 1); ++i) triangles.insert(triangles.end(), {0, 1 + i, 1 + (i + 1) % n});
  return Surface(std::move(positions), std::move(triangles));
}

// A triangle of the given size around (cx, cy) at heights z + tilt.
void around(double p[3][3], double cx, double cy, double z, double size, std::mt19937& random) {
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  for (int j = 0; j < 3; ++j) {
    const double angle = 2.0944 * j + 0.3 * jitter(random);
    p[j][0] = cx + size * std::cos(angle), p[j][1] = cy + size * std::sin(angle), p[j][2] = z + 0.2 * size * jitter(random);
  }
}

}  // namespace

TEST_CASE("over a flat fan a triangle lying on it across its centre is bounded by nothing") {
  const Surface flat = fan(7, [](int) { return 0.0; });
  const Stars stars(flat);
  const double p[3][3] = {{-0.2, -0.15, 0.0}, {0.25, -0.1, 0.0}, {0.02, 0.3, 0.0}};
  CHECK(fan_cut_bound(p, flat, stars, 0, 1.0) <= 1e-15);
  const double lifted[3][3] = {{-0.2, -0.15, 0.01}, {0.25, -0.1, 0.01}, {0.02, 0.3, 0.01}};
  CHECK(fan_cut_bound(lifted, flat, stars, 0, 1.0) == doctest::Approx(0.01).epsilon(1e-12));
  CHECK(fan_cut_bound(lifted, flat, stars, 0, 0.005) == kInfinity);  // beyond the limit
}

TEST_CASE("over a bumpy fan the bound is never under a dense sampling's distances") {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int bounded = 0;
  for (int round = 0; round < 60; ++round) {
    const int n = 4 + round % 9;
    std::vector<double> heights(static_cast<size_t>(n));
    for (double& h : heights) h = 0.3 * unit(random);
    const Surface bumpy = fan(n, [&](int i) { return heights[size_t(i)]; });
    const Stars stars(bumpy);
    double p[3][3];
    around(p, 0.2 * unit(random), 0.2 * unit(random), 0.05 * unit(random), 0.1 + 0.3 * (round % 5) / 5.0, random);
    const double bound = fan_cut_bound(p, bumpy, stars, 0, kInfinity);
    if (bound == kInfinity) continue;
    ++bounded;
    CHECK(bound >= sampled_max(p, bumpy) * (1 - 1e-12));
  }
  CHECK(bounded >= 40);  // not vacuous: fans turning once around their mean normal give a bound
}

TEST_CASE("an open fan, a triangle folded back, or triangles sharing no vertex give no bound") {
  const double p[3][3] = {{-0.2, -0.15, 0.0}, {0.25, -0.1, 0.0}, {0.02, 0.3, 0.0}};
  const Surface open = fan(6, [](int) { return 0.0; }, false);
  CHECK(fan_cut_bound(p, open, Stars(open), 0, 1.0) == kInfinity);
  // one rim vertex pulled across its neighbour: its two triangles turn against the fan
  std::vector<double> positions = {0, 0, 0};
  std::vector<int32_t> triangles;
  for (int i = 0; i < 6; ++i) {
    const double angle = 2 * 3.14159265358979 * (i == 2 ? 0.5 : i) / 6;
    positions.insert(positions.end(), {std::cos(angle), std::sin(angle), 0.0});
    triangles.insert(triangles.end(), {0, 1 + i, 1 + (i + 1) % 6});
  }
  const Surface folded(std::move(positions), std::move(triangles));
  CHECK(fan_cut_bound(p, folded, Stars(folded), 0, 1.0) == kInfinity);
  const Surface flat = fan(7, [](int) { return 0.0; });
  const Stars stars(flat);
  CHECK(shared_fan_cut_bound(p, flat, stars, 0, 2, 4, 1.0) <= 1e-15);  // all hold the centre
  CHECK(shared_fan_cut_bound(p, flat, stars, 0, 2, -1, 1.0) == kInfinity);
}

TEST_CASE("a fan turning twice around its centre covers space twice: its bound still holds") {
  std::vector<double> positions = {0, 0, 0};
  std::vector<int32_t> triangles;
  for (int i = 0; i < 12; ++i) {
    const double angle = 4 * 3.14159265358979 * i / 12;
    positions.insert(positions.end(), {std::cos(angle), std::sin(angle), 0.02 * i});
    triangles.insert(triangles.end(), {0, 1 + i, 1 + (i + 1) % 12});
  }
  const Surface twice(std::move(positions), std::move(triangles));
  const Stars stars(twice);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int bounded = 0;
  for (int round = 0; round < 20; ++round) {
    double p[3][3];
    around(p, 0.2 * unit(random), 0.2 * unit(random), 0.1 * unit(random), 0.3, random);
    const double bound = fan_cut_bound(p, twice, stars, 0, kInfinity);
    if (bound == kInfinity) continue;
    ++bounded;
    CHECK(bound >= sampled_max(p, twice) * (1 - 1e-12));
  }
  CHECK(bounded == 20);
}
