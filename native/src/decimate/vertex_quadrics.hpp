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
//
// With wedges (Hoppe 1999, as meshoptimizer's attribute quadrics): a vertex keeps α, G_j, E_j
// apart for each wedge, the corners around it that share attribute values, so a UV seam's or
// hard edge's two sides each have their own best s and the jump between them costs nothing.
// A vertex's quadric is then the plain part once minus each wedge's G_j G_jᵀ/α etc. A merge
// pairs each wedge with the other vertex's wedge whose fields agree best where they meet (at
// the midpoint of their area-weighted centroids, kept per wedge), when that choice is mutual;
// any other wedge stays apart while a slot is free.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "decimate/quadric.hpp"

namespace topstoc {

class VertexQuadrics {
 public:
  /// wedges > 0 (with channels): up to that many attribute parts per vertex (file comment).
  VertexQuadrics(int32_t vertices, int channels, int wedges = 0)
      : channels_(channels),
        wedges_(channels > 0 ? std::min(wedges, kMaxWedges) : 0),
        stride_(wedges_ > 0 ? 10 + wedges_ * wedge_size() : channels > 0 ? 11 + 4 * channels : 10),
        data_(size_t(vertices) * stride_, 0.0) {}

  int channels() const { return channels_; }
  int wedges() const { return wedges_; }
  int stride() const { return stride_; }
  /// The length of one face's record from face(): the plain quadric, α, then G_j, E_j per channel.
  int face_size() const { return channels_ > 0 ? 11 + 4 * channels_ : 10; }
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

  /// Writes face (p0, p1, p2)'s quadric into out (face_size() doubles): its plane weighted by its
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
  /// Wedge mode: adds a face record (face(), already scaled to this corner's share) to vertex
  /// v's plain part and to its wedge `slot`, whose centroid sum takes the face's `centroid`.
  void add_corner(int32_t v, int slot, const double* record, const double* centroid) {
    double* x = at(v);
    for (int i = 0; i < 10; ++i) x[i] += record[i];
    double* wedge = x + 10 + slot * wedge_size();
    const double alpha = record[10];
    wedge[0] += alpha;
    for (int i = 0; i < 3; ++i) wedge[1 + i] += alpha * centroid[i];
    for (int i = 0; i < 4 * channels_; ++i) wedge[4 + i] += record[11 + i];
  }

  void merge(int32_t into, int32_t from) {
    if (wedges_ > 0) return merge_wedges(at(into), at(from));
    add(into, at(from));
  }

  /// The plain quadric of u's (and v's, when v >= 0) sum with the attributes at their best.
  /// The sum is u merged into v, as merge(v, u) makes it.
  void reduced(int32_t u, int32_t v, Quadric& out) const {
    if (wedges_ > 0) return reduced_wedges(u, v, out);
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
  static constexpr int kMaxWedges = 8;

 private:
  int wedge_size() const { return 4 + 4 * channels_; }

  /// How far wedges a and b's attribute fields are apart (squared, summed over the channels)
  /// at the midpoint of their centroids.
  double wedge_gap(const double* a, const double* b) const {
    double p[3];
    for (int i = 0; i < 3; ++i) p[i] = 0.5 * (a[1 + i] / a[0] + b[1 + i] / b[0]);
    double gap = 0;
    for (int j = 0; j < channels_; ++j) {
      const double* ga = a + 4 + 4 * j;
      const double* gb = b + 4 + 4 * j;
      const double sa = (ga[0] * p[0] + ga[1] * p[1] + ga[2] * p[2] + ga[3]) / a[0];
      const double sb = (gb[0] * p[0] + gb[1] * p[1] + gb[2] * p[2] + gb[3]) / b[0];
      gap += (sa - sb) * (sa - sb);
    }
    return gap;
  }

  /// The wedge of vertex record x nearest to `wedge` (-1 when x has none).
  int nearest_wedge(const double* x, const double* wedge) const {
    int best = -1;
    double best_gap = 0;
    for (int k = 0; k < wedges_; ++k) {
      const double* w = x + 10 + k * wedge_size();
      if (!(w[0] > 0)) continue;
      const double gap = wedge_gap(w, wedge);
      if (best < 0 || gap < best_gap) best = k, best_gap = gap;
    }
    return best;
  }

  /// Adds vertex record `from` to `into`, pairing their wedges (file comment).
  void merge_wedges(double* into, const double* from) const {
    const int size = wedge_size();
    int target[kMaxWedges];
    bool used[kMaxWedges];
    for (int k = 0; k < wedges_; ++k) used[k] = into[10 + k * size] > 0;
    for (int k = 0; k < wedges_; ++k) {
      const double* w = from + 10 + k * size;
      target[k] = -1;
      if (!(w[0] > 0)) continue;
      const int near = nearest_wedge(into, w);
      if (near >= 0 && nearest_wedge(from, into + 10 + near * size) == k) {
        target[k] = near;
        continue;
      }
      for (int free = 0; free < wedges_ && target[k] < 0; ++free)
        if (!used[free]) target[k] = free, used[free] = true;
      if (target[k] < 0) target[k] = near;
    }
    for (int i = 0; i < 10; ++i) into[i] += from[i];
    for (int k = 0; k < wedges_; ++k)
      if (target[k] >= 0)
        for (int i = 0; i < size; ++i) into[10 + target[k] * size + i] += from[10 + k * size + i];
  }

  void reduced_wedges(int32_t u, int32_t v, Quadric& out) const {
    double sum[10 + kMaxWedges * (4 + 4 * kMaxChannels)];
    const double* base = at(v >= 0 ? v : u);
    for (int i = 0; i < stride_; ++i) sum[i] = base[i];
    if (v >= 0) merge_wedges(sum, at(u));
    for (int i = 0; i < 6; ++i) out.a[i] = sum[i];
    for (int i = 0; i < 3; ++i) out.b[i] = sum[6 + i];
    out.c = sum[9];
    for (int k = 0; k < wedges_; ++k) {
      const double* w = sum + 10 + k * wedge_size();
      const double alpha = w[0];
      if (!(alpha > 0)) continue;
      for (int j = 0; j < channels_; ++j) {
        const double* g = w + 4 + 4 * j;
        const double e = g[3];
        out.a[0] -= g[0] * g[0] / alpha, out.a[1] -= g[0] * g[1] / alpha, out.a[2] -= g[0] * g[2] / alpha;
        out.a[3] -= g[1] * g[1] / alpha, out.a[4] -= g[1] * g[2] / alpha, out.a[5] -= g[2] * g[2] / alpha;
        for (int i = 0; i < 3; ++i) out.b[i] -= e * g[i] / alpha;
        out.c -= e * e / alpha;
      }
    }
  }

  int channels_;
  int wedges_;
  int stride_;
  std::vector<double> data_;
};

}  // namespace topstoc
