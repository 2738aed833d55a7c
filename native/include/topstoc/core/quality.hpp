// Triangle quality: the aspect ratio of thesis eq. 4.2,
//   AR = e0 e1 e2 / (8 (s - e0)(s - e1)(s - e2)),  s = (e0 + e1 + e2) / 2,
// which is 1 for an equilateral triangle and grows without bound as the triangle degenerates.
#pragma once

#include <cstdint>

namespace topstoc {

struct AspectStats {
  double mean = 0.0;        ///< over triangles with positive area
  double max = 0.0;         ///< over triangles with positive area
  int32_t degenerate = 0;   ///< triangles of zero area (infinite aspect ratio)
};

/// Aspect ratio of one triangle (infinity when degenerate).
double aspect_ratio(const double* a, const double* b, const double* c);

/// positions: 3 per vertex; triangles: 3 per triangle.
AspectStats aspect_ratio_stats(const double* positions, const int32_t* triangles, int64_t num_triangles);

}  // namespace topstoc
