#include "topstoc/edit/polygon_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace topstoc {

namespace {

// Predicates use a tolerance relative to the lengths involved: near-degenerate configurations
// are treated as degenerate, which only ever makes the planar method give up (the caller then
// falls back to a 3D method) and never produces a sliver or a fold.
constexpr double kRelative = 1e-12;

struct Point {
  double x, y;
};

double cross(const Point& a, const Point& b, const Point& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

double length(const Point& a, const Point& b) { return std::hypot(b.x - a.x, b.y - a.y); }

// Sign of the turn a -> b -> c: +1 left, -1 right, 0 (nearly) collinear.
int orientation(const Point& a, const Point& b, const Point& c) {
  const double d = cross(a, b, c);
  const double scale = length(a, b) * (length(a, c) + length(b, c));
  if (d > kRelative * scale) return 1;
  if (d < -kRelative * scale) return -1;
  return 0;
}

// p lies on the closed segment [a, b], given that a, b, p are collinear.
bool within(const Point& a, const Point& b, const Point& p) {
  const double slack = kRelative * (length(a, b) + 1e-300);
  return std::min(a.x, b.x) - slack <= p.x && p.x <= std::max(a.x, b.x) + slack &&
         std::min(a.y, b.y) - slack <= p.y && p.y <= std::max(a.y, b.y) + slack;
}

bool segments_meet(const Point& a, const Point& b, const Point& c, const Point& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
         (o4 == 0 && within(c, d, b));
}

// Coordinates moved to the origin and scaled to unit size, so that tolerances mean the same for
// every hole.
std::vector<Point> normalized(const std::vector<double>& xy) {
  const size_t k = xy.size() / 2;
  std::vector<Point> p(k);
  double lo[2] = {xy[0], xy[1]}, hi[2] = {xy[0], xy[1]};
  for (size_t i = 0; i < k; ++i)
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], xy[2 * i + a]);
      hi[a] = std::max(hi[a], xy[2 * i + a]);
    }
  const double size = std::max(hi[0] - lo[0], hi[1] - lo[1]);
  const double scale = size > 0 ? 1.0 / size : 1.0;
  for (size_t i = 0; i < k; ++i) p[i] = {(xy[2 * i] - lo[0]) * scale, (xy[2 * i + 1] - lo[1]) * scale};
  return p;
}

// > 0 when d lies strictly inside the circumcircle of the counter-clockwise triangle abc.
bool in_circle(const Point& a, const Point& b, const Point& c, const Point& d) {
  const double adx = a.x - d.x, ady = a.y - d.y, bdx = b.x - d.x, bdy = b.y - d.y, cdx = c.x - d.x, cdy = c.y - d.y;
  const double ad = adx * adx + ady * ady, bd = bdx * bdx + bdy * bdy, cd = cdx * cdx + cdy * cdy;
  const double det = ad * (bdx * cdy - bdy * cdx) + bd * (cdx * ady - cdy * adx) + cd * (adx * bdy - ady * bdx);
  const double permanent = ad * (std::abs(bdx * cdy) + std::abs(bdy * cdx)) +
                           bd * (std::abs(cdx * ady) + std::abs(cdy * adx)) +
                           cd * (std::abs(adx * bdy) + std::abs(ady * bdx));
  return det > 1e-10 * permanent;
}

uint64_t pair_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

// Ear clipping over a doubly linked ring of corners.
bool clip_ears(const std::vector<Point>& p, const ForbiddenDiagonal& forbidden, std::vector<std::array<int32_t, 3>>& out) {
  const int32_t k = static_cast<int32_t>(p.size());
  std::vector<int32_t> prev(k), next(k);
  for (int32_t i = 0; i < k; ++i) {
    prev[i] = (i + k - 1) % k;
    next[i] = (i + 1) % k;
  }
  std::vector<uint8_t> convex(k), alive(k, 1);
  std::vector<int32_t> concave;  // corners that were not convex when last looked at (lazily pruned)
  auto classify = [&](int32_t i) {
    convex[i] = orientation(p[prev[i]], p[i], p[next[i]]) > 0;
    if (!convex[i]) concave.push_back(i);
  };
  for (int32_t i = 0; i < k; ++i) classify(i);
  auto is_ear = [&](int32_t i, int32_t remaining) {
    if (!convex[i]) return false;
    const int32_t a = prev[i], c = next[i];
    if (remaining > 3 && forbidden && forbidden(a, c)) return false;
    for (int32_t j : concave) {
      if (!alive[j] || convex[j] || j == a || j == i || j == c) continue;
      // Closed containment: a corner on the ear's boundary blocks it too.
      if (orientation(p[a], p[i], p[j]) >= 0 && orientation(p[i], p[c], p[j]) >= 0 &&
          orientation(p[c], p[a], p[j]) >= 0)
        return false;
    }
    return true;
  };
  int32_t remaining = k, i = 0, misses = 0;
  while (remaining > 3) {
    if (is_ear(i, remaining)) {
      const int32_t a = prev[i], c = next[i];
      out.push_back({a, i, c});
      alive[i] = 0;
      next[a] = c;
      prev[c] = a;
      --remaining;
      classify(a);
      classify(c);
      if (concave.size() > size_t(4 * remaining + 16)) {  // prune dead entries now and then
        concave.erase(std::remove_if(concave.begin(), concave.end(), [&](int32_t j) { return !alive[j] || convex[j]; }),
                      concave.end());
        std::sort(concave.begin(), concave.end());
        concave.erase(std::unique(concave.begin(), concave.end()), concave.end());
      }
      i = a;
      misses = 0;
    } else {
      i = next[i];
      if (++misses > remaining) return false;
    }
  }
  const int32_t a = prev[i], c = next[i];
  if (orientation(p[a], p[i], p[c]) <= 0) return false;
  out.push_back({a, i, c});
  return true;
}

// Lawson flips until every diagonal is locally Delaunay (or its flip is forbidden or would
// fold a triangle): the constrained Delaunay triangulation of the polygon.
void make_delaunay(const std::vector<Point>& p, const ForbiddenDiagonal& forbidden, std::vector<std::array<int32_t, 3>>& tris) {
  const int32_t k = static_cast<int32_t>(p.size());
  auto is_side = [&](int32_t a, int32_t b) { return (a + 1) % k == b || (b + 1) % k == a; };
  // Diagonal -> the two triangles holding it.
  std::unordered_map<uint64_t, std::array<int32_t, 2>> holders;
  holders.reserve(2 * tris.size());
  for (int32_t t = 0; t < int32_t(tris.size()); ++t)
    for (int c = 0; c < 3; ++c) {
      const int32_t a = tris[t][c], b = tris[t][(c + 1) % 3];
      if (is_side(a, b)) continue;
      auto it = holders.try_emplace(pair_key(a, b), std::array<int32_t, 2>{-1, -1}).first;
      it->second[it->second[0] < 0 ? 0 : 1] = t;
    }
  std::vector<uint64_t> stack;
  stack.reserve(holders.size());
  for (const auto& entry : holders) stack.push_back(entry.first);
  std::sort(stack.begin(), stack.end());  // deterministic order
  auto third = [&](const std::array<int32_t, 3>& t, int32_t a, int32_t b) {
    for (int c = 0; c < 3; ++c)
      if (t[c] != a && t[c] != b) return t[c];
    return -1;
  };
  auto replace_holder = [&](int32_t a, int32_t b, int32_t from, int32_t to) {
    if (is_side(a, b)) return;
    auto& h = holders[pair_key(a, b)];
    h[h[0] == from ? 0 : 1] = to;
  };
  size_t budget = 50 * tris.size() + 1000;  // Delaunay flips terminate; the budget guards rounding
  while (!stack.empty() && budget-- > 0) {
    const uint64_t key = stack.back();
    stack.pop_back();
    auto it = holders.find(key);
    if (it == holders.end()) continue;
    const int32_t t1 = it->second[0], t2 = it->second[1];
    if (t1 < 0 || t2 < 0) continue;
    // Orient so that t1 = (a, b, c) counter-clockwise and t2 holds b -> a with apex d.
    int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu);
    {
      const auto& t = tris[t1];
      int c0 = 0;
      while (t[c0] != a) ++c0;
      if (t[(c0 + 1) % 3] != b) std::swap(a, b);
    }
    const int32_t c = third(tris[t1], a, b), d = third(tris[t2], a, b);
    if (!in_circle(p[a], p[b], p[c], p[d])) continue;
    if (forbidden && forbidden(c, d)) continue;
    if (orientation(p[a], p[d], p[c]) <= 0 || orientation(p[d], p[b], p[c]) <= 0) continue;
    tris[t1] = {a, d, c};
    tris[t2] = {d, b, c};
    holders.erase(it);
    holders[pair_key(c, d)] = {t1, t2};
    replace_holder(a, d, t2, t1);
    replace_holder(b, c, t1, t2);
    for (const auto& e : {std::array<int32_t, 2>{a, d}, {d, b}, {b, c}, {c, a}})
      if (!is_side(e[0], e[1])) stack.push_back(pair_key(e[0], e[1]));
  }
}

}  // namespace

double polygon_area(const std::vector<double>& xy) {
  const size_t k = xy.size() / 2;
  double twice = 0.0;
  for (size_t i = 0; i < k; ++i) {
    const size_t j = (i + 1) % k;
    twice += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
  }
  return 0.5 * twice;
}

bool polygon_is_simple(const std::vector<double>& xy) {
  const int32_t k = static_cast<int32_t>(xy.size() / 2);
  if (k < 3) return false;
  const std::vector<Point> p = normalized(xy);
  // Consecutive sides may be collinear but must not fold back.
  for (int32_t i = 0; i < k; ++i) {
    const Point &a = p[(i + k - 1) % k], &b = p[i], &c = p[(i + 1) % k];
    if (length(a, b) <= kRelative || length(b, c) <= kRelative) return false;
    if (orientation(a, b, c) == 0 && (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y) < 0) return false;
  }
  // Sweep over sides sorted by their left end: only sides overlapping in x are compared.
  std::vector<int32_t> order(k);
  std::iota(order.begin(), order.end(), 0);
  auto left = [&](int32_t s) { return std::min(p[s].x, p[(s + 1) % k].x); };
  auto right = [&](int32_t s) { return std::max(p[s].x, p[(s + 1) % k].x); };
  std::sort(order.begin(), order.end(), [&](int32_t s, int32_t t) { return left(s) < left(t); });
  const double slack = 4 * kRelative;
  for (int32_t i = 0; i < k; ++i) {
    const int32_t s = order[i];
    const Point &a = p[s], &b = p[(s + 1) % k];
    const double s_low = std::min(a.y, b.y), s_high = std::max(a.y, b.y), s_right = right(s);
    for (int32_t j = i + 1; j < k && left(order[j]) <= s_right + slack; ++j) {
      const int32_t t = order[j];
      if (t == (s + 1) % k || s == (t + 1) % k) continue;  // consecutive: checked above
      const Point &c = p[t], &d = p[(t + 1) % k];
      if (std::max(c.y, d.y) < s_low - slack || std::min(c.y, d.y) > s_high + slack) continue;
      if (segments_meet(a, b, c, d)) return false;
    }
  }
  // A triangle needs a non-zero area; longer polygons have it once simple.
  return orientation(p[0], p[1], p[2]) != 0 || k > 3;
}

bool triangulate_polygon(const std::vector<double>& xy, const ForbiddenDiagonal& forbidden,
                         std::vector<std::array<int32_t, 3>>& triangles) {
  const std::vector<Point> p = normalized(xy);
  std::vector<std::array<int32_t, 3>> tris;
  tris.reserve(p.size());
  if (!clip_ears(p, forbidden, tris)) return false;
  make_delaunay(p, forbidden, tris);
  triangles.insert(triangles.end(), tris.begin(), tris.end());
  return true;
}

}  // namespace topstoc
