// surface_deviation: the from-input side against brute force over every collapsed triangle (its
// side middles measured once per side), the back side against brute force over the input, and
// the early stop against a rival: it stops only when
// the input's vertices already show a larger mean or a farther point, and never changes a value
// it does finish.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "decimate/collapser.hpp"
#include "decimate/deviation.hpp"
#include "collapse_setup.hpp"
#include "meshes.hpp"
#include "topstoc/core/mesh.hpp"

using topstoc::Collapser;
using topstoc::Deviation;
using topstoc::Rival;

namespace {

// The prepared mesh's own vertex and triangle order, so that collapser ids are mesh ids.
topstoc_test::Arrays internal(const topstoc::Mesh& mesh) {
  topstoc_test::Arrays out;
  out.positions.assign(mesh.position(0), mesh.position(0) + 3 * size_t(mesh.num_vertices()));
  out.triangles.assign(mesh.faces().begin(), mesh.faces().end());
  return out;
}

// Squared distance from p to the live triangles of `c` (brute force).
double to_collapsed2(const Collapser& c, const std::vector<int32_t>& triangles, const double* p) {
  double best = 1e300;
  for (size_t t = 0; 3 * t < triangles.size(); ++t) {
    if (!c.face_alive(int32_t(t))) continue;
    double q[3];
    best = std::min(best, topstoc::closest_point_on_triangle(p, c.position(triangles[3 * t]),
                                                             c.position(triangles[3 * t + 1]),
                                                             c.position(triangles[3 * t + 2]), q));
  }
  return best;
}

// Squared distance from p to the input's triangles (brute force).
double to_input2(const topstoc::InputSurface& input, const topstoc::Mesh& mesh, const double* p) {
  const std::vector<double>& at = input.surface->positions();
  double best = 1e300;
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* q = &mesh.faces()[3 * size_t(f)];
    double c[3];
    best = std::min(best, topstoc::closest_point_on_triangle(p, &at[3 * size_t(q[0])], &at[3 * size_t(q[1])],
                                                             &at[3 * size_t(q[2])], c));
  }
  return best;
}

}  // namespace

TEST_CASE("deviation from the input matches brute force, and a rival stops it only when the run loses") {
  const auto arrays = topstoc_test::torus(40, 20, 0.6, 0.25);  // inside [-1, 1]: normalised as is
  const topstoc::Mesh mesh(arrays.positions, arrays.triangles.data(), int64_t(arrays.triangles.size() / 3));
  const auto in = internal(mesh);
  const int32_t n = mesh.num_vertices();
  std::vector<int32_t> triangles = in.triangles, corners(triangles.size());
  for (size_t i = 0; i < corners.size(); ++i) corners[i] = int32_t(i);
  Collapser collapser(triangles, corners, topstoc_test::torus_setup(in));
  collapser.run({n / 10, 0});
  std::vector<int32_t> label(n);
  for (int32_t v = 0; v < n; ++v) label[v] = v;  // every input vertex starts as its own vertex
  const topstoc::InputSurface input(mesh, topstoc::normalised_input(mesh, collapser, 1));
  const Deviation full = topstoc::surface_deviation(mesh, input, label, collapser, triangles);
  REQUIRE(full.complete);
  REQUIRE(full.top2 > 0.0);

  // Each vertex holds at least its own distance and the farthest side middle or centre of its
  // triangles near the top; every value is one of the measured points' distances or less.
  double vertex_top2 = 0.0, sum = 0.0, area = 0.0;
  for (int32_t v = 0; v < n; ++v) {
    const double d2 = to_collapsed2(collapser, triangles, mesh.position(v));
    CHECK(full.vertex2[v] >= d2);
    vertex_top2 = std::max(vertex_top2, d2);
    sum += input.area[v] * std::sqrt(d2);
    area += input.area[v];
  }
  CHECK(full.mean == doctest::Approx(sum / area).epsilon(1e-12));
  int32_t raised = 0;  // vertices whose value a side middle or centre raised
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* q = &mesh.faces()[3 * size_t(f)];
    double found2 = 0.0, measured2 = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double *a = mesh.position(q[j]), *b = mesh.position(q[(j + 1) % 3]);
      const double middle[3] = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
      found2 = std::max(found2, to_collapsed2(collapser, triangles, middle));
      measured2 = std::max(measured2, to_collapsed2(collapser, triangles, a));
    }
    if (measured2 < 0.25 * vertex_top2) continue;  // not near the top: not measured inside
    for (int j = 0; j < 3; ++j) {
      CHECK(full.vertex2[q[j]] >= found2);
      raised += full.vertex2[q[j]] == found2 && found2 > to_collapsed2(collapser, triangles, mesh.position(q[j]));
    }
  }
  CHECK(raised > 0);

  // Back: each live triangle's corners, side middles and centre against brute force, their mean
  // by area, and every input vertex of a corner's cluster holding at least those distances.
  double back_sum = 0.0, back_area = 0.0;
  for (size_t t = 0; 3 * t < triangles.size(); ++t) {
    if (!collapser.face_alive(int32_t(t))) continue;
    const double* c[3] = {collapser.position(triangles[3 * t]), collapser.position(triangles[3 * t + 1]),
                          collapser.position(triangles[3 * t + 2])};
    double points[7][3];
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        points[j][k] = c[j][k];
        points[3 + j][k] = 0.5 * (c[j][k] + c[(j + 1) % 3][k]);
        points[6][k] = (c[0][k] + c[1][k] + c[2][k]) / 3.0;
      }
    double far2 = 0.0, root_sum = 0.0;
    for (const auto& point : points) {
      const double d2 = to_input2(input, mesh, point);
      far2 = std::max(far2, d2);
      root_sum += std::sqrt(d2);
    }
    const double u[3] = {c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]};
    const double w[3] = {c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]};
    const double cross[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double twice_area = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    back_sum += twice_area * root_sum / 7.0;
    back_area += twice_area;
    for (int32_t v = 0; v < n; ++v)
      for (int j = 0; j < 3; ++j)
        if (collapser.survivor(v) == triangles[3 * t + j]) CHECK(full.vertex2[v] >= far2);
  }
  CHECK(full.back_mean == doctest::Approx(back_sum / back_area).epsilon(1e-12));

  // A rival the run beats or ties: the same measure to the bit.
  const Rival loose{full.top2, full.mean};
  const Deviation tied = topstoc::surface_deviation(mesh, input, label, collapser, triangles, &loose);
  CHECK(tied.complete);
  CHECK(tied.vertex2 == full.vertex2);
  CHECK(tied.top2 == full.top2);
  CHECK(tied.mean == full.mean);
  // A smaller mean or a nearer farthest vertex than the run's: stopped, with the vertices' figures.
  const Rival smaller_mean{full.top2, 0.99 * full.mean}, nearer{0.99 * vertex_top2, full.mean};
  for (const Rival* rival : {&smaller_mean, &nearer}) {
    const Deviation lost = topstoc::surface_deviation(mesh, input, label, collapser, triangles, rival);
    CHECK_FALSE(lost.complete);
    CHECK(lost.mean == full.mean);
    CHECK(lost.top2 == doctest::Approx(vertex_top2).epsilon(1e-12));
  }
  // A farthest point found only beyond the vertices (here the back side's) does not stop the
  // measure at them.
  REQUIRE(vertex_top2 < full.top2);
  const Rival between{0.5 * (vertex_top2 + full.top2), full.mean};
  CHECK(topstoc::surface_deviation(mesh, input, label, collapser, triangles, &between).complete);
}
