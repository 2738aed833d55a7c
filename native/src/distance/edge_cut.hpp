// A bound on the distance from a triangle P to a surface B where P straddles an edge of B.
//
// Where two of P's corners have nearest triangles j and k of B that share an edge, P is cut in two
// by the plane through that edge and the two triangles' mean normal: on j's side the distance to
// j bounds it, on k's the distance to k, each convex over its part, so each peaks at a corner of
// that part (P's corners there and the cut points). This settles, for a few distances, a triangle
// lying across an edge of B, flat or bent, that one triangle's convex bound would leave open.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "topstoc/distance/bvh.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

namespace edge_cut_detail {

// Whether triangles a and b of `to` share an edge (its two vertices into edge).
inline bool shared_edge(const std::vector<int32_t>& t, int32_t a, int32_t b, int32_t edge[2]) {
  int count = 0;
  for (int i = 0; i < 3; ++i)
    for (int l = 0; l < 3; ++l)
      if (t[3 * size_t(a) + i] == t[3 * size_t(b) + l] && count < 2) edge[count++] = t[3 * size_t(a) + i];
  return count == 2;
}

inline int32_t third_corner(const std::vector<int32_t>& t, int32_t triangle, const int32_t edge[2]) {
  for (int i = 0; i < 3; ++i) {
    const int32_t v = t[3 * size_t(triangle) + i];
    if (v != edge[0] && v != edge[1]) return v;
  }
  return edge[0];
}

// A triangle's unit normal (zero for a degenerate one).
inline void normal_of(const Surface& to, int32_t triangle, double n[3]) {
  const auto& p = to.positions();
  const auto& t = to.triangles();
  const double* a = &p[3 * size_t(t[3 * size_t(triangle)])];
  const double* b = &p[3 * size_t(t[3 * size_t(triangle) + 1])];
  const double* c = &p[3 * size_t(t[3 * size_t(triangle) + 2])];
  double u[3], w[3];
  for (int i = 0; i < 3; ++i) u[i] = b[i] - a[i], w[i] = c[i] - a[i];
  n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int i = 0; i < 3; ++i) n[i] = length > 0 ? n[i] / length : 0.0;
}

inline double distance2_to(const Surface& to, int32_t triangle, const double* x) {
  const auto& p = to.positions();
  const int32_t* ids = &to.triangles()[3 * size_t(triangle)];
  double closest[3];
  return closest_point_on_triangle(x, &p[3 * size_t(ids[0])], &p[3 * size_t(ids[1])], &p[3 * size_t(ids[2])], closest);
}

}  // namespace edge_cut_detail

/// The cut bound of triangle p through the edge triangles j and k of `to` share, or +infinity
/// where they share none or a squared distance exceeds limit2. corner2(i, t): the squared distance
/// from p's corner i to triangle t (a caller may know some).
template <typename Corner2>
double edge_cut_bound(const double p[3][3], const Surface& to, int32_t j, int32_t k, double limit2,
                      const Corner2& corner2) {
  using namespace edge_cut_detail;
  constexpr double kNone = std::numeric_limits<double>::infinity();
  int32_t shared[2];
  if (j < 0 || k < 0 || j == k || !shared_edge(to.triangles(), j, k, shared)) return kNone;
  const double* e0 = &to.positions()[3 * size_t(shared[0])];
  const double* e1 = &to.positions()[3 * size_t(shared[1])];
  double nj[3], nk[3], e[3], m[3];
  normal_of(to, j, nj), normal_of(to, k, nk);
  for (int c = 0; c < 3; ++c) e[c] = e1[c] - e0[c], nj[c] += nk[c];
  m[0] = e[1] * nj[2] - e[2] * nj[1], m[1] = e[2] * nj[0] - e[0] * nj[2], m[2] = e[0] * nj[1] - e[1] * nj[0];
  const double* apex = &to.positions()[3 * size_t(third_corner(to.triangles(), j, shared))];  // j's side is m's +
  if ((apex[0] - e0[0]) * m[0] + (apex[1] - e0[1]) * m[1] + (apex[2] - e0[2]) * m[2] < 0)
    for (double& c : m) c = -c;
  double side[3];
  for (int i = 0; i < 3; ++i) side[i] = (p[i][0] - e0[0]) * m[0] + (p[i][1] - e0[1]) * m[1] + (p[i][2] - e0[2]) * m[2];
  double worst = 0.0;
  for (int i = 0; i < 3; ++i) {  // each corner against its side's triangle (on the plane: both)
    if (side[i] >= 0) worst = std::max(worst, corner2(i, j));
    if (side[i] <= 0) worst = std::max(worst, corner2(i, k));
    if (worst > limit2) return kNone;
  }
  for (int i = 0; i < 3; ++i) {  // the cut points: on both parts
    const int n = (i + 1) % 3;
    if (!((side[i] > 0 && side[n] < 0) || (side[i] < 0 && side[n] > 0))) continue;
    const double t = side[i] / (side[i] - side[n]);
    double x[3];
    for (int c = 0; c < 3; ++c) x[c] = p[i][c] + t * (p[n][c] - p[i][c]);
    worst = std::max({worst, distance2_to(to, j, x), distance2_to(to, k, x)});
    if (worst > limit2) return kNone;
  }
  return std::sqrt(worst);
}

}  // namespace topstoc
