// The fit's normal equations for results too large for a dense factorisation (tiny_fit.hpp):
// one symmetric positive definite matrix over the unknown vertices, its non-zeros where two
// unknowns share a triangle, solved for three right-hand sides (x, y, z) by conjugate gradients.
#pragma once

#include <cstdint>
#include <vector>

namespace topstoc {

class SparseNormal {
 public:
  /// faces: 3 vertex ids per triangle; unknown: per vertex its unknown (-1: fixed); k unknowns.
  SparseNormal(const std::vector<int32_t>& faces, const std::vector<int32_t>& unknown, int32_t k);

  /// Adds w to entry (r, c) (both unknowns of one triangle).
  void add(int32_t r, int32_t c, double w);
  double diagonal(int32_t r) const { return value_[diagonal_[r]]; }

  /// x (3 per unknown) from its start toward A x = b by Jacobi-preconditioned conjugate
  /// gradients, each coordinate apart, until the residual falls below tolerance x |b| or after
  /// max_iterations; one thread, so the same bits on any team size.
  void solve(const std::vector<double>& b, std::vector<double>& x, double tolerance, int32_t max_iterations) const;

 private:
  std::vector<int64_t> row_;      // CSR offsets
  std::vector<int32_t> column_;   // sorted within each row
  std::vector<double> value_;
  std::vector<int64_t> diagonal_;  // per row: the slot of its diagonal
};

}  // namespace topstoc
