#include "decimate/sparse_normal.hpp"

#include <algorithm>
#include <cmath>

namespace topstoc {

SparseNormal::SparseNormal(const std::vector<int32_t>& faces, const std::vector<int32_t>& unknown, int32_t k) {
  // Each row's columns: itself and the unknowns it shares a triangle with, sorted, once each.
  std::vector<std::vector<int32_t>> columns(static_cast<size_t>(k));
  for (int32_t r = 0; r < k; ++r) columns[r].push_back(r);
  for (size_t f = 0; f + 2 < faces.size(); f += 3)
    for (int j = 0; j < 3; ++j)
      for (int l = 0; l < 3; ++l) {
        const int32_t r = unknown[faces[f + j]], c = unknown[faces[f + l]];
        if (r >= 0 && c >= 0 && r != c) columns[r].push_back(c);
      }
  row_.assign(size_t(k) + 1, 0);
  diagonal_.resize(size_t(k));
  for (int32_t r = 0; r < k; ++r) {
    auto& cs = columns[r];
    std::sort(cs.begin(), cs.end());
    cs.erase(std::unique(cs.begin(), cs.end()), cs.end());
    row_[r + 1] = row_[r] + int64_t(cs.size());
    for (size_t i = 0; i < cs.size(); ++i) {
      if (cs[i] == r) diagonal_[r] = row_[r] + int64_t(i);
      column_.push_back(cs[i]);
    }
  }
  value_.assign(column_.size(), 0.0);
}

void SparseNormal::add(int32_t r, int32_t c, double w) {
  const auto first = column_.begin() + row_[r], last = column_.begin() + row_[r + 1];
  value_[size_t(std::lower_bound(first, last, c) - column_.begin())] += w;
}

void SparseNormal::solve(const std::vector<double>& b, std::vector<double>& x, double tolerance,
                         int32_t max_iterations) const {
  const size_t k = diagonal_.size();
  std::vector<double> r(k), z(k), p(k), q(k);
  auto multiply = [&](const std::vector<double>& v, std::vector<double>& out) {
    for (size_t i = 0; i < k; ++i) {
      double s = 0.0;
      for (int64_t e = row_[i]; e < row_[i + 1]; ++e) s += value_[e] * v[column_[e]];
      out[i] = s;
    }
  };
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> xa(k);
    double norm_b = 0.0;
    for (size_t i = 0; i < k; ++i) xa[i] = x[3 * i + axis], norm_b += b[3 * i + axis] * b[3 * i + axis];
    multiply(xa, q);
    double rz = 0.0, rr = 0.0;
    for (size_t i = 0; i < k; ++i) {
      r[i] = b[3 * i + axis] - q[i];
      z[i] = r[i] / value_[diagonal_[i]];
      p[i] = z[i];
      rz += r[i] * z[i], rr += r[i] * r[i];
    }
    const double limit = tolerance * tolerance * norm_b;
    for (int32_t it = 0; it < max_iterations && rr > limit && rz > 0.0; ++it) {
      multiply(p, q);
      double pq = 0.0;
      for (size_t i = 0; i < k; ++i) pq += p[i] * q[i];
      if (!(pq > 0.0)) break;
      const double alpha = rz / pq;
      double next_rz = 0.0;
      rr = 0.0;
      for (size_t i = 0; i < k; ++i) {
        xa[i] += alpha * p[i];
        r[i] -= alpha * q[i];
        z[i] = r[i] / value_[diagonal_[i]];
        next_rz += r[i] * z[i], rr += r[i] * r[i];
      }
      const double beta = next_rz / rz;
      rz = next_rz;
      for (size_t i = 0; i < k; ++i) p[i] = z[i] + beta * p[i];
    }
    for (size_t i = 0; i < k; ++i) x[3 * i + axis] = xa[i];
  }
}

}  // namespace topstoc
