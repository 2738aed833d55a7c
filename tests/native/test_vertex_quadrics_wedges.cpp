// Attribute quadrics per wedge (vertex_quadrics.hpp) against a brute-force sum over the faces of
// each wedge: squared plane distance plus the squared differences from the face's attribute
// field to the wedge's best value, each field solved here from the face's corner values.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "decimate/quadric.hpp"
#include "decimate/vertex_quadrics.hpp"

using topstoc::Quadric;
using topstoc::VertexQuadrics;

namespace {

struct Face {
  double p[3][3];
  std::vector<double> values;  // 3 corners × channels
  int wedge;
};

// The face's linear field through its corner values at x (the gradient in the face's plane,
// solved from the two edges by Cramer's rule on [e1; e2; n]).
double field(const Face& f, int channels, int j, const double* x) {
  double e1[3], e2[3];
  for (int i = 0; i < 3; ++i) e1[i] = f.p[1][i] - f.p[0][i], e2[i] = f.p[2][i] - f.p[0][i];
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double r[3] = {f.values[channels + j] - f.values[j], f.values[2 * channels + j] - f.values[j], 0.0};
  auto det = [](const double* a, const double* b, const double* c) {
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  };
  const double d = det(e1, e2, n);
  double g[3];
  for (int k = 0; k < 3; ++k) {
    double m1[3] = {e1[0], e1[1], e1[2]}, m2[3] = {e2[0], e2[1], e2[2]}, m3[3] = {n[0], n[1], n[2]};
    m1[k] = r[0], m2[k] = r[1], m3[k] = r[2];
    g[k] = det(m1, m2, m3) / d;
  }
  return f.values[j] + g[0] * (x[0] - f.p[0][0]) + g[1] * (x[1] - f.p[0][1]) + g[2] * (x[2] - f.p[0][2]);
}

double area_and_distance2(const Face& f, const double* x, double* distance2) {
  double e1[3], e2[3];
  for (int i = 0; i < 3; ++i) e1[i] = f.p[1][i] - f.p[0][i], e2[i] = f.p[2][i] - f.p[0][i];
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double d = (n[0] * (x[0] - f.p[0][0]) + n[1] * (x[1] - f.p[0][1]) + n[2] * (x[2] - f.p[0][2])) / len;
  *distance2 = d * d;
  return 0.5 * len;
}

// Σ over faces of area × (plane distance² + Σ_j (field − the wedge's best value)²), each face
// counted `share` times (a corner's third).
double brute_error(const std::vector<Face>& faces, int channels, int wedges, const double* x, double share) {
  double total = 0;
  for (int w = 0; w < wedges; ++w)
    for (int j = 0; j < channels; ++j) {
      double area = 0, sum = 0;
      for (const Face& f : faces)
        if (f.wedge == w) {
          double unused;
          const double a = area_and_distance2(f, x, &unused);
          area += a, sum += a * field(f, channels, j, x);
        }
      if (!(area > 0)) continue;
      for (const Face& f : faces)
        if (f.wedge == w) {
          double unused;
          const double a = area_and_distance2(f, x, &unused);
          const double s = field(f, channels, j, x) - sum / area;
          total += share * a * s * s;
        }
    }
  for (const Face& f : faces) {
    double d2;
    total += share * area_and_distance2(f, x, &d2) * d2;
  }
  return total;
}

void add(VertexQuadrics& q, int32_t v, const Face& f) {
  std::vector<double> record(q.face_size());
  REQUIRE(q.face(f.p[0], f.p[1], f.p[2], f.values.data(), record.data()));
  for (double& x : record) x /= 3.0;
  double centroid[3];
  for (int i = 0; i < 3; ++i) centroid[i] = (f.p[0][i] + f.p[1][i] + f.p[2][i]) / 3.0;
  q.add_corner(v, f.wedge, record.data(), centroid);
}

// A triangle in the plane z = 0 whose one channel is the field x + 0.3 y + jump.
Face flat(double ax, double ay, double bx, double by, double cx, double cy, double jump, int wedge) {
  Face f{{{ax, ay, 0}, {bx, by, 0}, {cx, cy, 0}}, {}, wedge};
  for (auto& p : f.p) f.values.push_back(p[0] + 0.3 * p[1] + jump);
  return f;
}

double reduced_error(const VertexQuadrics& q, int32_t u, int32_t v, const double* x) {
  Quadric r;
  q.reduced(u, v, r);
  return r.error(x);
}

}  // namespace

TEST_CASE("wedge quadrics equal the brute-force sum over each wedge's faces") {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int round = 0; round < 40; ++round) {
    const int channels = 1 + round % 3, wedges = 1 + round % 4;
    std::vector<Face> faces(2 + round % 7);
    for (Face& f : faces) {
      for (auto& p : f.p)
        for (double& c : p) c = coordinate(random);
      f.values.resize(3 * channels);
      for (double& s : f.values) s = coordinate(random);
      f.wedge = int(random() % wedges);
    }
    VertexQuadrics q(1, channels, wedges);
    for (const Face& f : faces) add(q, 0, f);
    for (int trial = 0; trial < 5; ++trial) {
      const double x[3] = {coordinate(random), coordinate(random), coordinate(random)};
      const double expected = brute_error(faces, channels, wedges, x, 1.0 / 3.0);
      CHECK(reduced_error(q, 0, -1, x) == doctest::Approx(expected).epsilon(1e-9).scale(1.0));
    }
  }
}

TEST_CASE("a seam's jump costs nothing with a wedge per side, and merges keep the sides apart") {
  // Vertex 0 on the seam x = 0 (left side's field jumps by 5 to the right's), vertex 1 further
  // along it, vertex 2 inside the left side.
  const std::vector<Face> seam0 = {flat(0, 0, -1, 0, 0, 1, 0.0, 0), flat(0, 0, 0, 1, 1, 0, 5.0, 1)};
  const std::vector<Face> seam1 = {flat(0, 1, -1, 1, 0, 2, 0.0, 0), flat(0, 1, 0, 2, 1, 1, 5.0, 1)};
  const std::vector<Face> left = {flat(-1, 0, -2, 0, -1, 1, 0.0, 0)};
  const double x[3] = {0.1, 0.7, 0.0};
  VertexQuadrics one(3, 1, 0), split(3, 1, 2);
  for (const Face& f : seam0) add(split, 0, f);
  for (const Face& f : seam1) add(split, 1, f);
  for (const Face& f : left) add(split, 2, f);
  std::vector<double> record(one.face_size());
  int32_t v = 0;
  for (const auto* faces : {&seam0, &seam1, &left}) {
    for (const Face& f : *faces) {
      REQUIRE(one.face(f.p[0], f.p[1], f.p[2], f.values.data(), record.data()));
      for (double& r : record) r /= 3.0;
      one.add(v, record.data());
    }
    ++v;
  }
  // One attribute part per vertex pays for the jump (both sides meet at the average).
  std::vector<Face> joined = seam0;
  for (Face& f : joined) f.wedge = 0;
  const double jump_cost = brute_error(joined, 1, 1, x, 1.0 / 3.0);
  CHECK(jump_cost > 1.0);
  CHECK(reduced_error(one, 0, -1, x) == doctest::Approx(jump_cost));
  CHECK(std::fabs(reduced_error(split, 0, -1, x)) < 1e-12);
  // Along the seam: left merges with left, right with right.
  CHECK(std::fabs(reduced_error(split, 1, 0, x)) < 1e-12);
  // The interior vertex joins the seam vertex's left wedge, not its right one.
  CHECK(std::fabs(reduced_error(split, 2, 0, x)) < 1e-12);
  split.merge(0, 1);
  split.merge(0, 2);
  CHECK(std::fabs(reduced_error(split, 0, -1, x)) < 1e-12);
  CHECK(reduced_error(one, 1, 0, x) > 1.0);
}

TEST_CASE("one wedge is the single attribute part of a vertex") {
  const std::vector<Face> faces = {flat(0, 0, -1, 0, 0, 1, 0.0, 0), flat(0, 0, 0, 1, 1, 0, 5.0, 0),
                                   flat(0, 0, 1, 0, 1, -1, 2.0, 0)};
  VertexQuadrics one(2, 1, 0), single(2, 1, 1);
  std::vector<double> record(one.face_size());
  for (int32_t v = 0; v < 2; ++v)
    for (const Face& f : faces) {
      REQUIRE(one.face(f.p[0], f.p[1], f.p[2], f.values.data(), record.data()));
      for (double& r : record) r /= 3.0;
      one.add(v, record.data());
      add(single, v, f);
    }
  const double x[3] = {0.2, -0.1, 0.3};
  CHECK(reduced_error(one, 0, 1, x) == doctest::Approx(reduced_error(single, 0, 1, x)).epsilon(1e-12));
  CHECK(reduced_error(one, 0, 1, x) > 1.0);
}
