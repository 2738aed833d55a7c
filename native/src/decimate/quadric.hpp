// Quadric error (Garland & Heckbert 1997): the area-weighted sum of squared distances from a
// point to a set of planes, E(x) = xᵀAx + 2bᵀx + c. Summing two quadrics sums their planes, so
// a cluster's quadric measures how far a point is from all the input triangles it stands for.
#pragma once

#include <algorithm>
#include <cmath>

namespace topstoc {

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations. a: row-major,
/// destroyed; values: eigenvalues; vectors: columns are eigenvectors (row-major).
inline void symmetric_eigen(double a[9], double values[3], double vectors[9]) {
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

struct Quadric {
  double a[6] = {0, 0, 0, 0, 0, 0};  ///< symmetric A: xx xy xz yy yz zz
  double b[3] = {0, 0, 0};
  double c = 0;

  /// Adds the plane through p0, p1, p2, weighted by the triangle's area; no-op for zero area.
  void add_triangle(const double* p0, const double* p1, const double* p2) {
    double u[3], w[3];
    for (int i = 0; i < 3; ++i) u[i] = p1[i] - p0[i], w[i] = p2[i] - p0[i];
    double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len == 0) return;
    const double area = 0.5 * len;
    for (double& x : n) x /= len;
    const double d = -(n[0] * p0[0] + n[1] * p0[1] + n[2] * p0[2]);
    a[0] += area * n[0] * n[0], a[1] += area * n[0] * n[1], a[2] += area * n[0] * n[2];
    a[3] += area * n[1] * n[1], a[4] += area * n[1] * n[2], a[5] += area * n[2] * n[2];
    for (int i = 0; i < 3; ++i) b[i] += area * d * n[i];
    c += area * d * d;
  }

  void add(const Quadric& q) {
    for (int i = 0; i < 6; ++i) a[i] += q.a[i];
    for (int i = 0; i < 3; ++i) b[i] += q.b[i];
    c += q.c;
  }

  /// Summed squared distance of x to the planes (area-weighted); >= 0 up to rounding.
  double error(const double* x) const {
    const double ax0 = a[0] * x[0] + a[1] * x[1] + a[2] * x[2];
    const double ax1 = a[1] * x[0] + a[3] * x[1] + a[4] * x[2];
    const double ax2 = a[2] * x[0] + a[4] * x[1] + a[5] * x[2];
    return x[0] * ax0 + x[1] * ax1 + x[2] * ax2 + 2.0 * (b[0] * x[0] + b[1] * x[1] + b[2] * x[2]) + c;
  }

  /// The point minimising the error, A x = -b, into x; false when A is close to singular
  /// (determinant below 1e-6 of the cube of its mean eigenvalue: a flat or straight
  /// neighbourhood, where the minimum is a plane or a line, not a point).
  bool minimum(double x[3]) const {
    const double c00 = a[3] * a[5] - a[4] * a[4], c01 = a[2] * a[4] - a[1] * a[5], c02 = a[1] * a[4] - a[2] * a[3];
    const double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
    const double mean = (a[0] + a[3] + a[5]) / 3.0;
    if (!(mean > 0) || !(std::abs(det) > 1e-6 * mean * mean * mean)) return false;
    const double c11 = a[0] * a[5] - a[2] * a[2], c12 = a[1] * a[2] - a[0] * a[4], c22 = a[0] * a[3] - a[1] * a[1];
    // x = -A^-1 b with the adjugate (A symmetric).
    const double inverse = -1.0 / det;
    x[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) * inverse;
    x[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) * inverse;
    x[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) * inverse;
    return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
  }

  /// t minimising the error along p + t d (unclamped; 0 when the error is flat along d).
  double line_minimum(const double* p, const double* d) const {
    const double ad0 = a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
    const double ad1 = a[1] * d[0] + a[3] * d[1] + a[4] * d[2];
    const double ad2 = a[2] * d[0] + a[4] * d[1] + a[5] * d[2];
    const double curvature = d[0] * ad0 + d[1] * ad1 + d[2] * ad2;
    const double slope = p[0] * ad0 + p[1] * ad1 + p[2] * ad2 + b[0] * d[0] + b[1] * d[1] + b[2] * d[2];
    return curvature > 0 ? -slope / curvature : 0.0;
  }

  /// The step from p towards the minimum along the directions the quadric constrains: the
  /// minimiser of A x = -b by the pseudo-inverse, x = p + A⁺(-b - A p), keeping eigenvalues above
  /// 1e-3 of the largest (a flat or cylindrical neighbourhood moves only across itself). False
  /// (move zero) for a zero quadric.
  bool truncated_step(const double* p, double move[3]) const {
    move[0] = move[1] = move[2] = 0.0;
    double m[9] = {a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]};
    double r[3];
    for (int i = 0; i < 3; ++i) r[i] = -b[i] - (m[3 * i] * p[0] + m[3 * i + 1] * p[1] + m[3 * i + 2] * p[2]);
    double values[3], vectors[9];
    symmetric_eigen(m, values, vectors);
    const double largest = std::max({std::abs(values[0]), std::abs(values[1]), std::abs(values[2])});
    if (!(largest > 0)) return false;
    for (int e = 0; e < 3; ++e) {
      if (std::abs(values[e]) < 1e-3 * largest) continue;
      const double proj = (vectors[e] * r[0] + vectors[3 + e] * r[1] + vectors[6 + e] * r[2]) / values[e];
      for (int i = 0; i < 3; ++i) move[i] += proj * vectors[3 * i + e];
    }
    return std::isfinite(move[0]) && std::isfinite(move[1]) && std::isfinite(move[2]);
  }
};

}  // namespace topstoc
