// Per-vertex quadrics for the collapses, optionally with attribute channels (UVs, colours,
// normals): the generalised quadric of Hoppe (1999, "New quadric metric for simplifying meshes
// with appearance attributes"), a cheaper form of Garland & Heckbert (1998).
//
// On an input face of area w, unit normal n and offset d, each attribute channel j is the
// linear field s_j(p) = g_j·p + d_j through its corner values (g_j in the face's plane). A vertex
// at p with attribute values s costs
//
//     E(p, s) = Σ_faces w [ (n·p + d)² + Σ_j (g_j·p + d_j − s_j)² ],
//
// the squared distance to the faces' planes plus the squared differences from their attribute
// fields. A vertex stores the sums A = Σ w (nnᵀ + Σ_j g_j g_jᵀ), b, c (a plain quadric), the area
// α = Σ w and per channel G_j = Σ w g_j, E_j = Σ w d_j. The best s_j for a position p is
// (G_j·p + E_j)/α, and putting it in leaves a plain quadric in p again:
//
//     A' = A − Σ_j G_j G_jᵀ/α,  b' = b − Σ_j E_j G_j/α,  c' = c − Σ_j E_j²/α,
//
// which is zero where one linear field explains every face's attributes (a single face, a
// planar UV map) and grows where the attributes bend or jump. So the collapse order and the
// optimal placement see the attributes without solving a larger system. The weights are
// applied to the values before the faces are added (see RefineParams::attributes).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "decimate/quadric.hpp"

namespace topstoc {

class VertexQuadrics {
 public:
  VertexQuadrics(int32_t vertices, int channels)
      : channels_(channels), stride_(channels > 0 ? 11 + 4 * channels : 10), data_(size_t(vertices) * stride_, 0.0) {}

  int channels() const { return channels_; }
  int stride() const { return stride_; }
  double* at(int32_t v) { return &data_[size_t(v) * stride_]; }
  const double* at(int32_t v) const { return &data_[size_t(v) * stride_]; }

  /// The plain quadric of face (p0, p1, p2), its plane weighted by its area, into out (10
  /// doubles), and the area into *area. False (out untouched) for a face of zero area.
  static bool plane(const double* p0, const double* p1, const double* p2, double* out, double* area) {
    double e1[3], e2[3];
    for (int i = 0; i < 3; ++i) e1[i] = p1[i] - p0[i], e2[i] = p2[i] - p0[i];
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(len2 > 0)) return false;
    const double len = std::sqrt(len2), w = 0.5 * len;
    const double u[3] = {n[0] / len, n[1] / len, n[2] / len};
    const double d = -(u[0] * p0[0] + u[1] * p0[1] + u[2] * p0[2]);
    out[0] = w * u[0] * u[0], out[1] = w * u[0] * u[1], out[2] = w * u[0] * u[2];
    out[3] = w * u[1] * u[1], out[4] = w * u[1] * u[2], out[5] = w * u[2] * u[2];
    for (int i = 0; i < 3; ++i) out[6 + i] = w * d * u[i];
    out[9] = w * d * d;
    *area = w;
    return true;
  }

  /// Writes face (p0, p1, p2)'s quadric into out (stride() doubles): its plane weighted by its
  /// area and, with channels, its attribute fields through `values` (3 corners × channels).
  /// Returns false (out untouched) for a face of zero area.
  bool face(const double* p0, const double* p1, const double* p2, const double* values, double* out) const {
    double w;
    if (!plane(p0, p1, p2, out, &w)) return false;
    if (channels_ == 0) return true;
    out[10] = w;
    double e1[3], e2[3];
    for (int i = 0; i < 3; ++i) e1[i] = p1[i] - p0[i], e2[i] = p2[i] - p0[i];
    const double g11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    const double g12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
    const double g22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    const double len2 = 4.0 * w * w;  // |e1 × e2|², the Gram determinant
    for (int j = 0; j < channels_; ++j) {
      // g in the face's plane with g·e1 = s1 − s0, g·e2 = s2 − s0 (Gram system).
      const double s0 = values[j], ds1 = values[channels_ + j] - s0, ds2 = values[2 * channels_ + j] - s0;
      const double a = (g22 * ds1 - g12 * ds2) / len2, b = (g11 * ds2 - g12 * ds1) / len2;
      const double g[3] = {a * e1[0] + b * e2[0], a * e1[1] + b * e2[1], a * e1[2] + b * e2[2]};
      const double dj = s0 - (g[0] * p0[0] + g[1] * p0[1] + g[2] * p0[2]);
      out[0] += w * g[0] * g[0], out[1] += w * g[0] * g[1], out[2] += w * g[0] * g[2];
      out[3] += w * g[1] * g[1], out[4] += w * g[1] * g[2], out[5] += w * g[2] * g[2];
      for (int i = 0; i < 3; ++i) out[6 + i] += w * dj * g[i];
      out[9] += w * dj * dj;
      double* channel = out + 11 + 4 * j;
      for (int i = 0; i < 3; ++i) channel[i] = w * g[i];
      channel[3] = w * dj;
    }
    return true;
  }

  /// Adds a plane with unit normal u and offset d, weight w, to the geometric part of q.
  static void add_plane(double* q, const double* u, double d, double w) {
    q[0] += w * u[0] * u[0], q[1] += w * u[0] * u[1], q[2] += w * u[0] * u[2];
    q[3] += w * u[1] * u[1], q[4] += w * u[1] * u[2], q[5] += w * u[2] * u[2];
    for (int i = 0; i < 3; ++i) q[6 + i] += w * d * u[i];
    q[9] += w * d * d;
  }

  void add(int32_t v, const double* q) {
    double* x = at(v);
    for (int i = 0; i < 10; ++i) x[i] += q[i];  // the plain quadric: a fixed loop the compiler unrolls
    for (int i = 10; i < stride_; ++i) x[i] += q[i];
  }
  void merge(int32_t into, int32_t from) { add(into, at(from)); }

  /// The plain quadric of u's (and v's, when v >= 0) sum with the attributes at their best.
  void reduced(int32_t u, int32_t v, Quadric& out) const {
    const double* qu = at(u);
    if (channels_ == 0) {
      for (int i = 0; i < 6; ++i) out.a[i] = qu[i];
      for (int i = 0; i < 3; ++i) out.b[i] = qu[6 + i];
      out.c = qu[9];
      if (v >= 0) {
        const double* qv = at(v);
        for (int i = 0; i < 6; ++i) out.a[i] += qv[i];
        for (int i = 0; i < 3; ++i) out.b[i] += qv[6 + i];
        out.c += qv[9];
      }
      return;
    }
    double sum[11 + 4 * kMaxChannels];
    const double* qv = v >= 0 ? at(v) : nullptr;
    for (int i = 0; i < stride_; ++i) sum[i] = qu[i] + (qv ? qv[i] : 0.0);
    for (int i = 0; i < 6; ++i) out.a[i] = sum[i];
    for (int i = 0; i < 3; ++i) out.b[i] = sum[6 + i];
    out.c = sum[9];
    const double alpha = sum[10];
    if (!(alpha > 0)) return;
    for (int j = 0; j < channels_; ++j) {
      const double* g = sum + 11 + 4 * j;
      const double e = g[3];
      out.a[0] -= g[0] * g[0] / alpha, out.a[1] -= g[0] * g[1] / alpha, out.a[2] -= g[0] * g[2] / alpha;
      out.a[3] -= g[1] * g[1] / alpha, out.a[4] -= g[1] * g[2] / alpha, out.a[5] -= g[2] * g[2] / alpha;
      for (int i = 0; i < 3; ++i) out.b[i] -= e * g[i] / alpha;
      out.c -= e * e / alpha;
    }
  }

  static constexpr int kMaxChannels = 16;

 private:
  int channels_;
  int stride_;
  std::vector<double> data_;
};

}  // namespace topstoc
