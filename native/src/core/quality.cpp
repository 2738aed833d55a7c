#include "topstoc/core/quality.hpp"
#include "topstoc/core/parallel.hpp"

#include <cmath>
#include <limits>

namespace topstoc {

namespace {
double distance(const double* a, const double* b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
}  // namespace

double aspect_ratio(const double* a, const double* b, const double* c) {
  const double e0 = distance(a, b), e1 = distance(b, c), e2 = distance(c, a);
  const double s = 0.5 * (e0 + e1 + e2);
  const double denominator = 8.0 * (s - e0) * (s - e1) * (s - e2);
  if (!(denominator > 0.0)) return std::numeric_limits<double>::infinity();
  const double ar = e0 * e1 * e2 / denominator;
  return std::isfinite(ar) ? ar : std::numeric_limits<double>::infinity();
}

AspectStats aspect_ratio_stats(const double* positions, const int32_t* triangles, int64_t num_triangles) {
  AspectStats stats;
  double sum = 0.0, max = 0.0;
  int64_t counted = 0, degenerate = 0;
#pragma omp parallel for schedule(static) reduction(+ : sum, counted, degenerate) reduction(max : max) if (num_triangles >= kParallelMin)
  for (int64_t t = 0; t < num_triangles; ++t) {
    const int32_t* tri = triangles + 3 * t;
    const double ar = aspect_ratio(positions + 3 * size_t(tri[0]), positions + 3 * size_t(tri[1]),
                                   positions + 3 * size_t(tri[2]));
    if (std::isinf(ar)) {
      ++degenerate;
    } else {
      sum += ar;
      ++counted;
      max = ar > max ? ar : max;
    }
  }
  stats.mean = counted ? sum / double(counted) : 0.0;
  stats.max = max;
  stats.degenerate = static_cast<int32_t>(degenerate);
  return stats;
}

}  // namespace topstoc
