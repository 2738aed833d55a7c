#include "topstoc/core/validate.hpp"

#include <cfloat>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace topstoc {

void require_finite_position(const double* positions, int64_t v) {
  const double* p = positions + 3 * v;
  if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) return;
  std::ostringstream s;
  s << "vertex " << v << " has a non-finite coordinate (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  throw std::invalid_argument(s.str());
}

void require_finite_positions(const double* positions, int64_t num_vertices) {
  // A branch-free scan first (it vectorizes; |x| <= max is false for NaN and infinities); the
  // slow loop that names the vertex only runs when something is wrong.
  bool all_finite = true;
  for (int64_t i = 0; i < 3 * num_vertices; ++i) all_finite &= std::fabs(positions[i]) <= DBL_MAX;
  if (all_finite) return;
  for (int64_t v = 0; v < num_vertices; ++v) require_finite_position(positions, v);
}

void require_indices_in_range(const int32_t* indices, int64_t rows, int columns, int64_t num_vertices,
                              const char* what) {
  // A branch-free scan first (it vectorizes); the loop that names the row only runs when
  // something is out of range.
  bool all_in_range = true;
  for (int64_t i = 0; i < rows * columns; ++i) all_in_range &= (indices[i] >= 0) & (int64_t(indices[i]) < num_vertices);
  if (all_in_range) return;
  for (int64_t r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      const int32_t v = indices[columns * r + c];
      if (v < 0 || v >= num_vertices)
        throw std::invalid_argument(std::string(what) + " " + std::to_string(r) + " refers to vertex " +
                                    std::to_string(v) + ", but vertex indices must lie in [0, " +
                                    std::to_string(num_vertices) + ")");
    }
}

}  // namespace topstoc
