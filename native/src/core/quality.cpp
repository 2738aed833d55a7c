#include "topstoc/core/quality.hpp"
#include "ordered_sum.hpp"

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
  struct Partial {
    double sum = 0.0, max = 0.0;
    int64_t counted = 0, degenerate = 0;
  };
  // Fixed blocks summed in order (ordered_sum.hpp): the mean is the same to the bit on any
  // number of threads (an OpenMP reduction's last bits followed the thread count).
  const Partial total = ordered_reduce<Partial>(
      num_triangles,
      [&](Partial& p, int64_t t) {
        const int32_t* tri = triangles + 3 * t;
        const double ar = aspect_ratio(positions + 3 * size_t(tri[0]), positions + 3 * size_t(tri[1]),
                                       positions + 3 * size_t(tri[2]));
        if (std::isinf(ar)) {
          ++p.degenerate;
        } else {
          p.sum += ar;
          ++p.counted;
          p.max = ar > p.max ? ar : p.max;
        }
      },
      [](Partial& into, const Partial& p) {
        into.sum += p.sum;
        into.counted += p.counted;
        into.degenerate += p.degenerate;
        into.max = p.max > into.max ? p.max : into.max;
      });
  AspectStats stats;
  stats.mean = total.counted ? total.sum / double(total.counted) : 0.0;
  stats.max = total.max;
  stats.degenerate = static_cast<int32_t>(total.degenerate);
  return stats;
}

}  // namespace topstoc
