#include "distance/fan_cut.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "topstoc/distance/bvh.hpp"

namespace topstoc {

namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();
constexpr int kMostTriangles = int(Stars::kWideStar);  // wider fans are left to the other bounds

double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
void cross(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
}

// v's fan: per triangle, its two other corners in the triangle's own order after v (the sector runs
// from the first spoke to the second), the spokes' offsets from v and the two planes' normals.
struct Fan {
  int count = 0;
  int32_t triangle[kMostTriangles];
  double normal[kMostTriangles][2][3];  // per sector: its two planes' normals, pointing inside
  // False where the fan is too large, not closed (each spoke the start of one sector and the end of
  // another), or a sector is not turned the way of the fan's mean normal by less than half a turn.
  // Then the sectors chain around v, each turn covering space once: every point lies in one.
  bool set(const Surface& s, const Stars& stars, int32_t v) {
    count = int(stars.end(v) - stars.begin(v));
    if (count < 3 || count > kMostTriangles) return false;
    const double* c = &s.positions()[3 * size_t(v)];
    int32_t from[kMostTriangles], to[kMostTriangles];
    double e[kMostTriangles][3], f[kMostTriangles][3], n[kMostTriangles][3], axis[3] = {0, 0, 0};
    for (int i = 0; i < count; ++i) {
      triangle[i] = stars.triangle(stars.begin(v) + i);
      const int32_t* ids = &s.triangles()[3 * size_t(triangle[i])];
      const int r = ids[0] == v ? 0 : ids[1] == v ? 1 : 2;
      from[i] = ids[(r + 1) % 3], to[i] = ids[(r + 2) % 3];
      for (int k = 0; k < 3; ++k)
        e[i][k] = s.positions()[3 * size_t(from[i]) + k] - c[k], f[i][k] = s.positions()[3 * size_t(to[i]) + k] - c[k];
      cross(e[i], f[i], n[i]);
      for (int k = 0; k < 3; ++k) axis[k] += n[i][k];
    }
    for (int i = 0; i < count; ++i) {
      int starts = 0, ends = 0;
      for (int l = 0; l < count; ++l) starts += from[l] == from[i], ends += to[l] == from[i];
      if (starts != 1 || ends != 1) return false;
    }
    for (int i = 0; i < count; ++i) {
      if (!(dot(axis, n[i]) > 0)) return false;
      cross(axis, e[i], normal[i][0]);
      cross(f[i], axis, normal[i][1]);
    }
    return true;
  }
};

// Clips the polygon (count points) to the side of the plane through c with normal n where
// dot(n, x - c) >= 0; returns the points kept.
int clip(const double (*in)[3], int count, const double* c, const double* n, double (*out)[3]) {
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const double* p = in[i];
    const double* q = in[(i + 1) % count];
    double dp[3], dq[3];
    for (int k = 0; k < 3; ++k) dp[k] = p[k] - c[k], dq[k] = q[k] - c[k];
    const double sp = dot(n, dp), sq = dot(n, dq);
    if (sp >= 0) std::copy_n(p, 3, out[kept++]);
    if ((sp >= 0) != (sq >= 0)) {
      const double t = sp / (sp - sq);
      for (int k = 0; k < 3; ++k) out[kept][k] = p[k] + t * (q[k] - p[k]);
      ++kept;
    }
  }
  return kept;
}

}  // namespace

double fan_cut_bound(const double p[3][3], const Surface& to, const Stars& stars, int32_t v, double limit) {
  Fan fan;
  if (!fan.set(to, stars, v)) return kNone;
  const auto& positions = to.positions();
  const double* c = &positions[3 * size_t(v)];
  const double limit2 = limit * limit;
  double worst = 0.0;
  for (int i = 0; i < fan.count; ++i) {
    double ring[2][5][3];
    for (int j = 0; j < 3; ++j) std::copy_n(p[j], 3, ring[0][j]);
    int count = clip(ring[0], 3, c, fan.normal[i][0], ring[1]);
    count = count > 0 ? clip(ring[1], count, c, fan.normal[i][1], ring[0]) : 0;
    const int32_t* ids = &to.triangles()[3 * size_t(fan.triangle[i])];
    for (int m = 0; m < count; ++m) {
      double closest[3];
      worst = std::max(worst, closest_point_on_triangle(ring[0][m], &positions[3 * size_t(ids[0])],
                                                        &positions[3 * size_t(ids[1])], &positions[3 * size_t(ids[2])],
                                                        closest));
      if (worst > limit2) return kNone;
    }
  }
  return std::sqrt(worst);
}

double shared_fan_cut_bound(const double p[3][3], const Surface& to, const Stars& stars, int32_t j, int32_t k,
                            int32_t l, double limit) {
  if (j < 0 || k < 0 || l < 0) return kNone;
  const auto& t = to.triangles();
  auto holds = [&](int32_t triangle, int32_t v) {
    return t[3 * size_t(triangle)] == v || t[3 * size_t(triangle) + 1] == v || t[3 * size_t(triangle) + 2] == v;
  };
  double bound = kNone;
  for (int i = 0; i < 3; ++i) {
    const int32_t v = t[3 * size_t(j) + i];
    if (holds(k, v) && holds(l, v)) bound = std::min(bound, fan_cut_bound(p, to, stars, v, limit));
  }
  return bound;
}

}  // namespace topstoc
