#include "topstoc/decimate/placement.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/decimate/quadric.hpp"

#include <algorithm>
#include <cmath>

namespace topstoc {

namespace {

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations.
// a: row-major, destroyed; values: eigenvalues; vectors: columns are eigenvectors (row-major).
void symmetric_eigen(double a[9], double values[3], double vectors[9]) {
  for (int i = 0; i < 9; ++i) vectors[i] = (i % 4 == 0) ? 1.0 : 0.0;
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
    if (off < 1e-30) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const double apq = a[3 * p + q];
        if (std::abs(apq) < 1e-300) continue;
        const double theta = (a[3 * q + q] - a[3 * p + p]) / (2.0 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = a[3 * k + p], akq = a[3 * k + q];
          a[3 * k + p] = c * akp - s * akq;
          a[3 * k + q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = a[3 * p + k], aqk = a[3 * q + k];
          a[3 * p + k] = c * apk - s * aqk;
          a[3 * q + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = vectors[3 * k + p], vkq = vectors[3 * k + q];
          vectors[3 * k + p] = c * vkp - s * vkq;
          vectors[3 * k + q] = s * vkp + c * vkq;
        }
      }
  }
  for (int i = 0; i < 3; ++i) values[i] = a[4 * i];
}

}  // namespace

std::vector<double> filtered_positions(const Mesh& mesh, const FeatureLayout& layout,
                                       const std::vector<int32_t>& samples, const Clustering& clustering) {
  const int32_t k = static_cast<int32_t>(samples.size());
  const int32_t n = mesh.num_vertices();
  const auto& label = clustering.label;
  const auto& faces = mesh.faces();
  // Quadrics hold squared areas: with coordinates of 1e80 they overflow (all-NaN output), with
  // 1e-80 they underflow. Work in coordinates centred on the bounding box and scaled by its
  // half extent (halves taken first so that neither the centre nor the extent overflows).
  double low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) low[i] = std::min(low[i], mesh.position(v)[i]), high[i] = std::max(high[i], mesh.position(v)[i]);
  double center[3], extent = 0;
  for (int i = 0; i < 3; ++i) {
    center[i] = n > 0 ? 0.5 * low[i] + 0.5 * high[i] : 0.0;
    extent = std::max(extent, n > 0 ? 0.5 * high[i] - 0.5 * low[i] : 0.0);
  }
  std::vector<double> out(3 * size_t(k));
  for (int32_t s = 0; s < k; ++s)
    for (int i = 0; i < 3; ++i) out[3 * size_t(s) + i] = mesh.position(samples[s])[i];
  if (!(extent > 0) || !std::isfinite(extent)) return out;
  std::vector<double> unit(3 * size_t(n));
  for (int32_t v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) unit[3 * size_t(v) + i] = (mesh.position(v)[i] - center[i]) / extent;
  auto at = [&](int32_t v) { return &unit[3 * size_t(v)]; };
  std::vector<Quadric> quadrics(k);
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* t = &faces[3 * size_t(f)];
    Quadric plane;
    plane.add_triangle(at(t[0]), at(t[1]), at(t[2]));
    const int32_t l[3] = {label[t[0]], label[t[1]], label[t[2]]};
    for (int j = 0; j < 3; ++j)
      if (!((j > 0 && l[j] == l[0]) || (j > 1 && l[j] == l[1]))) quadrics[l[j]].add(plane);  // each cluster once
  }
  // Radius of each cluster around its sample: the bound on how far the sample may move.
  std::vector<double> radius2(k, 0.0);
  for (int32_t v = 0; v < n; ++v) {
    if (label[v] < 0) continue;
    const double* p = at(v);
    const double* s = at(samples[label[v]]);
    const double d2 = (p[0] - s[0]) * (p[0] - s[0]) + (p[1] - s[1]) * (p[1] - s[1]) + (p[2] - s[2]) * (p[2] - s[2]);
    radius2[label[v]] = std::max(radius2[label[v]], d2);
  }
#pragma omp parallel for schedule(static) if (k >= kParallelMin)
  for (int32_t s = 0; s < k; ++s) {
    const double* p = at(samples[s]);
    double* x = &out[3 * size_t(s)];
    if (layout.vertex_feature[samples[s]]) continue;
    const Quadric& q = quadrics[s];
    double a[9] = {q.a[0], q.a[1], q.a[2], q.a[1], q.a[3], q.a[4], q.a[2], q.a[4], q.a[5]};
    const double a_copy[9] = {a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8]};
    double values[3], vectors[9];
    symmetric_eigen(a, values, vectors);
    const double largest = std::max({std::abs(values[0]), std::abs(values[1]), std::abs(values[2])});
    if (!(largest > 0)) continue;
    // The minimiser solves A x = -b: x = p + A^+ (-b - A p), the pseudo-inverse keeping
    // directions with eigenvalue > 1e-3 max.
    double r[3];
    for (int i = 0; i < 3; ++i)
      r[i] = -q.b[i] - (a_copy[3 * i] * p[0] + a_copy[3 * i + 1] * p[1] + a_copy[3 * i + 2] * p[2]);
    double move[3] = {0, 0, 0};
    for (int e = 0; e < 3; ++e) {
      if (std::abs(values[e]) < 1e-3 * largest) continue;
      const double proj = (vectors[e] * r[0] + vectors[3 + e] * r[1] + vectors[6 + e] * r[2]) / values[e];
      for (int i = 0; i < 3; ++i) move[i] += proj * vectors[3 * i + e];
    }
    const double len2 = move[0] * move[0] + move[1] * move[1] + move[2] * move[2];
    const double scale = len2 > radius2[s] && len2 > 0 ? std::sqrt(radius2[s] / len2) : 1.0;
    double moved[3];
    for (int i = 0; i < 3; ++i) moved[i] = (p[i] + scale * move[i]) * extent + center[i];
    if (std::isfinite(moved[0]) && std::isfinite(moved[1]) && std::isfinite(moved[2]))
      for (int i = 0; i < 3; ++i) x[i] = moved[i];
  }
  return out;
}

}  // namespace topstoc
