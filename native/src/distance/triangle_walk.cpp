#include "distance/triangle_walk.hpp"

#include <utility>

#include "distance/vertex_stars.hpp"
#include "topstoc/distance/bvh.hpp"

namespace topstoc {

TriangleWalk::TriangleWalk(const Surface& s, const Stars& stars)
    : s_(s), stars_(stars), across_(3 * size_t(s.num_triangles()), kUnknown) {}

int32_t TriangleWalk::across(int32_t f, int j) const {
  int32_t& known = across_[3 * size_t(f) + size_t(j)];
  if (known != kUnknown) return known;
  const auto& t = s_.triangles();
  int32_t a = t[3 * size_t(f) + size_t(j)], b = t[3 * size_t(f) + size_t((j + 1) % 3)];
  if (stars_.end(b) - stars_.begin(b) < stars_.end(a) - stars_.begin(a)) std::swap(a, b);  // a fan's centre is b
  known = -1;
  // the first other triangle around a holding b (one of them where the side is non-manifold)
  for (int64_t i = stars_.begin(a); i < stars_.end(a); ++i) {
    const int32_t g = stars_.triangle(i);
    const int32_t* c = &t[3 * size_t(g)];
    if (g != f && (c[0] == b || c[1] == b || c[2] == b)) return known = g;
  }
  return known;
}

double TriangleWalk::distance2(const double* x, int32_t triangle) const {
  const auto& p = s_.positions();
  const int32_t* c = &s_.triangles()[3 * size_t(triangle)];
  double closest[3];
  return closest_point_on_triangle(x, &p[3 * size_t(c[0])], &p[3 * size_t(c[1])], &p[3 * size_t(c[2])], closest);
}

// The side of the triangle that x lies farthest beyond, seen along its normal, among those with a
// triangle across (-1: none; beyond a border only, the walk goes on along it where it can).
int TriangleWalk::beyond(const double* x, int32_t triangle) const {
  const auto& p = s_.positions();
  const int32_t* c = &s_.triangles()[3 * size_t(triangle)];
  const double* q[3] = {&p[3 * size_t(c[0])], &p[3 * size_t(c[1])], &p[3 * size_t(c[2])]};
  double e1[3], e2[3], n[3];
  for (int k = 0; k < 3; ++k) e1[k] = q[1][k] - q[0][k], e2[k] = q[2][k] - q[0][k];
  n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  double outside[3];  // squared distance beyond side j (times the squared area), 0 where inside
  for (int j = 0; j < 3; ++j) {
    const double* a = q[j];
    const double* b = q[(j + 1) % 3];
    double e[3], w[3];
    for (int k = 0; k < 3; ++k) e[k] = b[k] - a[k], w[k] = x[k] - a[k];
    // (e x w) . n: where x lies against side j (negative beyond it)
    const double turn = (e[1] * w[2] - e[2] * w[1]) * n[0] + (e[2] * w[0] - e[0] * w[2]) * n[1] +
                        (e[0] * w[1] - e[1] * w[0]) * n[2];
    outside[j] = turn < 0 ? turn * turn / (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) : 0.0;
  }
  int side = -1;
  for (int j = 0; j < 3; ++j)
    if (outside[j] > 0 && (side < 0 || outside[j] > outside[side]) && across(triangle, j) >= 0) side = j;
  return side;
}

TriangleWalk::End TriangleWalk::walk(const double* x, int32_t start, int max_steps, double close) const {
  int32_t at = start, from = -1;
  int step = 0;
  for (; step <= max_steps; ++step) {
    const int side = beyond(x, at);
    if (side < 0) break;  // over this triangle, or beyond a border only
    const int32_t next = across(at, side);
    if (next == from) break;
    if (step == max_steps) return {distance2(x, at), at, false};
    from = at, at = next;
  }
  // Then, unless within `close`, to a nearer edge neighbour while there is one (x over a triangle
  // next to a crease, or beyond a ridge or a border, may lie nearer to another).
  End end{distance2(x, at), at, true};
  if (end.distance2 <= close * close) return end;
  for (; step <= max_steps; ++step) {
    int32_t next = -1;
    double next2 = end.distance2;
    for (int j = 0; j < 3; ++j) {
      const int32_t g = across(end.triangle, j);
      if (g < 0 || g == from) continue;
      const double d2 = distance2(x, g);
      if (d2 < next2) next2 = d2, next = g;
    }
    if (next < 0) return end;
    from = end.triangle, end.distance2 = next2, end.triangle = next;
  }
  end.settled = false;
  return end;
}

std::vector<int32_t> walk_order(const Surface& s, const Stars& stars) {
  std::vector<char> reached(size_t(s.num_triangles()), 0), spread(size_t(s.num_vertices()), 0);
  std::vector<int32_t> order;
  order.reserve(size_t(s.num_triangles()));
  for (int32_t first = 0; first < s.num_triangles(); ++first) {
    if (reached[size_t(first)]) continue;
    reached[size_t(first)] = 1;
    order.push_back(first);
    for (size_t i = order.size() - 1; i < order.size(); ++i)
      for (int j = 0; j < 3; ++j) {
        const int32_t v = s.triangles()[3 * size_t(order[i]) + size_t(j)];
        if (spread[size_t(v)]) continue;  // each vertex's triangles are queued once
        spread[size_t(v)] = 1;
        for (int64_t k = stars.begin(v); k < stars.end(v); ++k)
          if (const int32_t g = stars.triangle(k); !reached[size_t(g)]) reached[size_t(g)] = 1, order.push_back(g);
      }
  }
  return order;
}

}  // namespace topstoc
