#include "topstoc/core/self_intersections.hpp"
#include "topstoc/core/parallel.hpp"

#include <tetgen.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>

namespace topstoc {

namespace {

// Exact sign of the orientation of d relative to the plane (a, b, c).
int orient(const double* a, const double* b, const double* c, const double* d) {
  static std::once_flag init;
  std::call_once(init, [] { exactinit(0, 0, 1, 1.0, 1.0, 1.0); });  // exact arithmetic, no static filter
  const double o = orient3d(const_cast<double*>(a), const_cast<double*>(b), const_cast<double*>(c), const_cast<double*>(d));
  return (o > 0) - (o < 0);
}

// A point off the plane of triangle (a, b, c), exactly: orientations against it decide sides
// within the plane (the plane through p, q and this point cuts the triangle's plane along pq).
// One of a + s e_x, a + s e_y, a + s e_z is off any plane through a; returns false when all
// three are on it, i.e. when the triangle has no area.
bool lifted(const double* a, const double* b, const double* c, double* out) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  double scale = 0.0;
  for (int k = 0; k < 3; ++k) scale = std::max({scale, std::abs(u[k]), std::abs(v[k])});
  if (!(scale > 0)) return false;
  int axes[3] = {0, 1, 2};
  std::sort(axes, axes + 3, [&](int i, int j) { return std::abs(n[i]) > std::abs(n[j]); });
  for (int axis : axes) {
    for (int k = 0; k < 3; ++k) out[k] = a[k] + (k == axis ? scale : 0.0);
    if (orient(a, b, c, out) != 0) return true;
  }
  return false;
}

// Closed segments pq and rs in the plane (orientation within the plane through `up`).
bool segments_meet_2d(const double* p, const double* q, const double* r, const double* s, const double* up) {
  const int o1 = orient(p, q, up, r), o2 = orient(p, q, up, s), o3 = orient(r, s, up, p), o4 = orient(r, s, up, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  auto on_segment = [&](const double* a, const double* b, const double* x) {  // x collinear with ab
    for (int k = 0; k < 3; ++k)
      if (x[k] < std::min(a[k], b[k]) || x[k] > std::max(a[k], b[k])) return false;
    return true;
  };
  return (o1 == 0 && on_segment(p, q, r)) || (o2 == 0 && on_segment(p, q, s)) || (o3 == 0 && on_segment(r, s, p)) ||
         (o4 == 0 && on_segment(r, s, q));
}

// Point x of the plane in the closed triangle (a, b, c).
bool inside_2d(const double* a, const double* b, const double* c, const double* x, const double* up) {
  const int o1 = orient(a, b, up, x), o2 = orient(b, c, up, x), o3 = orient(c, a, up, x);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

// Closed segment de against closed triangle abc.
bool segment_meets_triangle(const double* d, const double* e, const double* a, const double* b, const double* c) {
  const int od = orient(a, b, c, d), oe = orient(a, b, c, e);
  if (od * oe > 0) return false;
  if (od == 0 && oe == 0) {  // coplanar
    double up[3];
    if (!lifted(a, b, c, up)) return true;  // no area: reported on its own anyway
    return inside_2d(a, b, c, d, up) || inside_2d(a, b, c, e, up) || segments_meet_2d(d, e, a, b, up) ||
           segments_meet_2d(d, e, b, c, up) || segments_meet_2d(d, e, c, a, up);
  }
  // The line de crosses the plane inside the segment; is the crossing in the triangle?
  const int s1 = orient(d, e, a, b), s2 = orient(d, e, b, c), s3 = orient(d, e, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

bool degenerate(const double* a, const double* b, const double* c) {
  double up[3];
  return !lifted(a, b, c, up);
}

// A triangle naming one vertex twice: a segment or a point, not a triangle.
bool repeats_vertex(const int32_t* t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

}  // namespace

bool triangles_intersect(const double* positions, const int32_t* t1, const int32_t* t2) {
  // The shared-vertex cases below need three distinct corners per triangle.
  if (repeats_vertex(t1) || repeats_vertex(t2))
    throw std::invalid_argument("triangles_intersect: a triangle names one vertex twice");
  auto p = [&](int32_t v) { return positions + 3 * size_t(v); };
  int shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) shared += t1[i] == t2[j];
  if (shared == 3) return true;  // the same triangle twice
  if (shared == 2) {
    // Folded onto each other: the two opposite corners coplanar and on the same side of the edge.
    int u = -1, v = -1, w1 = -1, w2 = -1;
    for (int i = 0; i < 3; ++i) {
      const bool in2 = t1[i] == t2[0] || t1[i] == t2[1] || t1[i] == t2[2];
      if (!in2) w1 = t1[i];
      else if (u < 0) u = t1[i];
      else v = t1[i];
    }
    for (int j = 0; j < 3; ++j)
      if (t2[j] != u && t2[j] != v) w2 = t2[j];
    if (orient(p(u), p(v), p(w1), p(w2)) != 0) return false;
    double up[3];
    if (!lifted(p(u), p(v), p(w1), up)) return true;
    return orient(p(u), p(v), up, p(w1)) * orient(p(u), p(v), up, p(w2)) > 0;
  }
  if (shared == 1) {
    // Only the edges opposite the shared vertex can reach into the other triangle.
    auto opposite = [&](const int32_t* t, const int32_t* other, int32_t& a, int32_t& b) {
      a = b = -1;
      for (int i = 0; i < 3; ++i)
        if (t[i] != other[0] && t[i] != other[1] && t[i] != other[2]) (a < 0 ? a : b) = t[i];
    };
    int32_t a, b, q, r;
    opposite(t1, t2, a, b);
    opposite(t2, t1, q, r);
    return segment_meets_triangle(p(a), p(b), p(t2[0]), p(t2[1]), p(t2[2])) ||
           segment_meets_triangle(p(q), p(r), p(t1[0]), p(t1[1]), p(t1[2]));
  }
  for (int i = 0; i < 3; ++i) {
    if (segment_meets_triangle(p(t1[i]), p(t1[(i + 1) % 3]), p(t2[0]), p(t2[1]), p(t2[2]))) return true;
    if (segment_meets_triangle(p(t2[i]), p(t2[(i + 1) % 3]), p(t1[0]), p(t1[1]), p(t1[2]))) return true;
  }
  return false;
}

std::vector<std::pair<int32_t, int32_t>> self_intersections(const double* positions, int32_t num_vertices,
                                                            const int32_t* triangles, int32_t num_triangles,
                                                            int64_t max_pairs, const uint8_t* only_with) {
  std::vector<std::pair<int32_t, int32_t>> pairs;
  if (num_triangles == 0) return pairs;
  // Bounding boxes and a grid whose cells are about twice the mean box size.
  std::vector<double> box(6 * size_t(num_triangles));
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, mean = 0.0;
  for (int32_t t = 0; t < num_triangles; ++t) {
    double* b = &box[6 * size_t(t)];
    for (int k = 0; k < 3; ++k) {
      b[k] = INFINITY;
      b[3 + k] = -INFINITY;
    }
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) {
        const double x = positions[3 * size_t(triangles[3 * size_t(t) + c]) + k];
        b[k] = std::min(b[k], x);
        b[3 + k] = std::max(b[3 + k], x);
      }
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b[k]);
      hi[k] = std::max(hi[k], b[3 + k]);
      mean += (b[3 + k] - b[k]) / 3.0;
    }
  }
  (void)num_vertices;
  mean /= num_triangles;
  double cell = 2.0 * mean;
  for (int k = 0; k < 3; ++k) cell = std::max(cell, (hi[k] - lo[k]) / 1024.0);
  if (!(cell > 0)) cell = 1.0;
  if (!std::isfinite(cell)) cell = INFINITY;  // coordinates near the double range: one cell
  // Cell coordinates clamped in double first: converting NaN or an out-of-range double to an
  // integer is undefined behaviour (non-finite or huge coordinates land in the border cells).
  const auto cell_of = [&](double offset, int64_t last) -> int64_t {
    const double x = offset / cell;
    return x >= 0 ? (x < double(last) ? int64_t(x) : last) : 0;
  };
  int64_t dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = cell_of(hi[k] - lo[k], 1024) + 1;
  auto cell_range = [&](int32_t t, int64_t* from, int64_t* to) {
    const double* b = &box[6 * size_t(t)];
    for (int k = 0; k < 3; ++k) {
      from[k] = cell_of(b[k] - lo[k], dims[k] - 1);
      to[k] = cell_of(b[3 + k] - lo[k], dims[k] - 1);
    }
  };
  const auto each_cell = [&](int32_t t, auto&& visit) {
    int64_t from[3], to[3];
    cell_range(t, from, to);
    for (int64_t x = from[0]; x <= to[0]; ++x)
      for (int64_t y = from[1]; y <= to[1]; ++y)
        for (int64_t z = from[2]; z <= to[2]; ++z) visit((x * dims[1] + y) * dims[2] + z);
  };
  // With only_with, only the cells of flagged triangles matter: every pair tested has one.
  std::vector<int64_t> wanted;
  if (only_with) {
    for (int32_t t = 0; t < num_triangles; ++t)
      if (only_with[t] && !repeats_vertex(triangles + 3 * size_t(t))) each_cell(t, [&](int64_t c) { wanted.push_back(c); });
    std::sort(wanted.begin(), wanted.end());
    wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  }
  // (cell, triangle) entries, grouped by cell.
  std::vector<std::pair<int64_t, int32_t>> entries;
  entries.reserve(only_with ? 8 * wanted.size() : 4 * size_t(num_triangles));
  for (int32_t t = 0; t < num_triangles; ++t) {
    if (repeats_vertex(triangles + 3 * size_t(t))) continue;  // no area: reported as (t, t) only
    each_cell(t, [&](int64_t c) {
      if (!only_with || std::binary_search(wanted.begin(), wanted.end(), c)) entries.emplace_back(c, t);
    });
  }
  std::sort(entries.begin(), entries.end());
  std::vector<size_t> starts;
  for (size_t i = 0; i < entries.size(); ++i)
    if (i == 0 || entries[i].first != entries[i - 1].first) starts.push_back(i);
  starts.push_back(entries.size());

  for (int32_t t = 0; t < num_triangles; ++t) {
    if (only_with && !only_with[t]) continue;
    const double* a = positions + 3 * size_t(triangles[3 * size_t(t)]);
    if (repeats_vertex(triangles + 3 * size_t(t)) || degenerate(a, positions + 3 * size_t(triangles[3 * size_t(t) + 1]), positions + 3 * size_t(triangles[3 * size_t(t) + 2])))
      pairs.emplace_back(t, t);
  }
  const int64_t cells = int64_t(starts.size()) - 1;
  // Threads pay off on large meshes only (and a parallel region costs a time slice on a busy machine).
  std::atomic<int64_t> next_cell{0};
  parallel_region(num_triangles > 50000 ? max_threads() : 1, [&](Team& team) {
    std::vector<std::pair<int32_t, int32_t>> found;
    team.for_dynamic(next_cell, cells, 64, [&](int64_t c) {
      for (size_t i = starts[c]; i < starts[c + 1]; ++i) {
        if (only_with && !only_with[entries[i].second]) continue;  // paired from the flagged side
        for (size_t j = only_with ? starts[c] : i + 1; j < starts[c + 1]; ++j) {
          int32_t s = entries[i].second, t = entries[j].second;
          if (only_with && (j == i || (only_with[t] && j < i))) continue;  // flagged pairs once
          if (s > t) std::swap(s, t);
          const double* bs = &box[6 * size_t(s)];
          const double* bt = &box[6 * size_t(t)];
          bool overlap = true;
          for (int k = 0; k < 3; ++k) overlap = overlap && bs[k] <= bt[3 + k] && bt[k] <= bs[3 + k];
          if (!overlap) continue;
          // Test each pair once: in the first cell both boxes share.
          int64_t from_s[3], to_s[3], from_t[3], to_t[3];
          cell_range(s, from_s, to_s);
          cell_range(t, from_t, to_t);
          const int64_t first =
              (std::max(from_s[0], from_t[0]) * dims[1] + std::max(from_s[1], from_t[1])) * dims[2] + std::max(from_s[2], from_t[2]);
          if (first != entries[i].first) continue;
          if (triangles_intersect(positions, triangles + 3 * size_t(s), triangles + 3 * size_t(t))) found.emplace_back(s, t);
        }
      }
    });
    team.critical([&] { pairs.insert(pairs.end(), found.begin(), found.end()); });
  });
  std::sort(pairs.begin(), pairs.end());
  if (max_pairs > 0 && int64_t(pairs.size()) > max_pairs) pairs.resize(max_pairs);
  return pairs;
}

}  // namespace topstoc
