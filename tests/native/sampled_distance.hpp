// The largest distance from a dense sampling of a triangle to a surface, by the BVH's exact closest
// points: a lower bound of the triangle's max distance, against which the tests check upper bounds.
#pragma once

#include <algorithm>
#include <cmath>

#include "topstoc/distance/hausdorff.hpp"

inline double sampled_max(const double p[3][3], const topstoc::Surface& to) {
  const int steps = 40;
  double best = 0.0;
  for (int i = 0; i <= steps; ++i)
    for (int j = 0; i + j <= steps; ++j) {
      const double u = double(i) / steps, v = double(j) / steps, w = 1 - u - v;
      double x[3];
      for (int k = 0; k < 3; ++k) x[k] = w * p[0][k] + u * p[1][k] + v * p[2][k];
      best = std::max(best, std::sqrt(to.bvh().closest(x).distance2));
    }
  return best;
}
