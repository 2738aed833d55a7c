#include "distance/vertex_stars.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace topstoc {

namespace {

double distance2(const double* a, const double* b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

}  // namespace

double distance_to_triangle(const double* x, const Surface& s, int32_t f) {
  const auto& p = s.positions();
  const int32_t* t = &s.triangles()[3 * size_t(f)];
  double closest[3];
  return std::sqrt(closest_point_on_triangle(x, &p[3 * size_t(t[0])], &p[3 * size_t(t[1])], &p[3 * size_t(t[2])],
                                             closest));
}

Stars::Stars(const Surface& a) : a_(a), offset_(size_t(a.num_vertices()) + 1, 0) {
  const auto& t = a.triangles();
  for (int32_t v : t) ++offset_[size_t(v) + 1];
  for (size_t v = 1; v < offset_.size(); ++v) offset_[v] += offset_[v - 1];
  triangle_.resize(t.size());
  std::vector<int64_t> next(offset_.begin(), offset_.end() - 1);
  for (size_t c = 0; c < t.size(); ++c) triangle_[size_t(next[size_t(t[c])]++)] = int32_t(c / 3);
  std::vector<int32_t> corners;
  for (int32_t v = 0; v < a.num_vertices(); ++v) {
    if (!wide(v)) continue;
    corners.clear();
    for (int64_t i = begin(v); i < end(v); ++i)
      for (int c = 0; c < 3; ++c) corners.push_back(t[3 * size_t(triangle(i)) + c]);
    wide_.push_back(v);
    trees_.push_back(std::make_unique<TriangleBvh>(a.positions().data(), corners.data(), end(v) - begin(v)));
  }
}

Stars::Nearest Stars::nearest(const double* y, int32_t v) const {
  if (wide(v)) {  // the tree's ties go to the lower slot of the star, as the loop's below
    const size_t tree = size_t(std::lower_bound(wide_.begin(), wide_.end(), v) - wide_.begin());
    const ClosestHit hit = trees_[tree]->closest(y);
    return {std::sqrt(hit.distance2), triangle(begin(v) + hit.triangle)};
  }
  Nearest out{std::numeric_limits<double>::infinity(), -1};
  for (int64_t i = begin(v); i < end(v); ++i) {
    const double d = distance_to_triangle(y, a_, triangle(i));
    if (d < out.distance) out.distance = d, out.triangle = triangle(i);
  }
  return out;
}

StarBound star_distance_bound(const double* y, int32_t start, const Surface& a, const Stars& stars) {
  const auto& positions = a.positions();
  const auto& triangles = a.triangles();
  int32_t v = start;
  double best2 = distance2(y, &positions[3 * size_t(v)]);
  auto step_through = [&](int32_t f, bool& moved) {  // to f's nearest corner if nearer than v
    for (int c = 0; c < 3; ++c) {
      const int32_t w = triangles[3 * size_t(f) + c];
      const double d2 = distance2(y, &positions[3 * size_t(w)]);
      if (d2 < best2) best2 = d2, v = w, moved = true;
    }
  };
  for (bool moved = true; moved;) {
    moved = false;
    const int32_t from = v;
    if (stars.wide(from)) {
      step_through(stars.nearest(y, from).triangle, moved);
      continue;
    }
    for (int64_t i = stars.begin(from); i < stars.end(from); ++i) step_through(stars.triangle(i), moved);
  }
  const Stars::Nearest near = stars.nearest(y, v);  // v is a corner of each: no farther than v
  return {near.distance, v, near.triangle};
}

StarBound star_exact_distance(const double* y, StarBound bound, double reach, const Surface& a,
                              const VertexGrid& grid, const Stars& stars) {
  const double radius = bound.distance + reach;
  grid.for_each_near(y, radius, [&](int32_t v) {
    if (distance2(y, &a.positions()[3 * size_t(v)]) > radius * radius) return;
    const Stars::Nearest near = stars.nearest(y, v);
    if (near.distance < bound.distance) bound.distance = near.distance, bound.triangle = near.triangle;
  });
  return bound;
}

}  // namespace topstoc
