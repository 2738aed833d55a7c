#include "distance/projected_bound.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "distance/triangle_walk.hpp"
#include "topstoc/distance/bvh.hpp"

namespace topstoc {

namespace {

constexpr double kNoBound = std::numeric_limits<double>::infinity();
// A triangle of B counts as facing T when its projection keeps at least this share of its area
// (nearly vertical ones would give heights by dividing by almost nothing).
constexpr double kFacing = 1e-6;
// Boundary sides this close to T (relative to its longest side) count as crossing it.
constexpr double kMargin = 1e-9;
// projected_bound_over's margin, relative to T's coordinates' magnitude: a few hundred times the
// rounding of the (u, v) coordinates, so that a boundary of U through a corner or along a side of
// T (a result lying on its original) costs next to nothing in the bound.
constexpr double kRoundingMargin = 1e-13;
// projected_bound_over's margin may grow up to kMargin's where its reach stays within this share of
// the limit (a result's corner a little off its original's boundary still settles).
constexpr double kMarginShare = 0.5;
// Sides paired by sorting up to this many, by hashing above (paired).
constexpr size_t kSortedSides = 96;

double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
void cross(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
}
// (b - a) x (c - a) in the plane: positive when a, b, c turn counterclockwise.
double turn(const double* a, const double* b, const double* c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

// T's plane: (u, v) coordinates in it and the height along its unit normal.
struct Frame {
  double origin[3], u[3], v[3], n[3];
  // q's offset from the origin (its coordinates are this offset's dot products with u, v and n).
  void offset(const double* q, double* d) const {
    for (int k = 0; k < 3; ++k) d[k] = q[k] - origin[k];
  }
  void project(const double* q, double* out) const {
    double d[3];
    offset(q, d);
    out[0] = dot(d, u), out[1] = dot(d, v), out[2] = dot(d, n);
  }
  // The distance from the point (a, b) of T's plane to the triangle with the given corners.
  double distance(const double* ab, const double* corners) const {
    double x[3], closest[3];
    for (int k = 0; k < 3; ++k) x[k] = origin[k] + ab[0] * u[k] + ab[1] * v[k];
    return std::sqrt(closest_point_on_triangle(x, corners, corners + 3, corners + 6, closest));
  }
};

// T's three sides (counterclockwise) and their lengths in its plane, for `meets`.
struct Sides {
  const double (*t)[3];
  double length[3];
  explicit Sides(const double (*corners)[3]) : t(corners) {
    for (int i = 0; i < 3; ++i) {
      const double* s = t[i];
      const double* e = t[(i + 1) % 3];
      length[i] = std::sqrt((e[0] - s[0]) * (e[0] - s[0]) + (e[1] - s[1]) * (e[1] - s[1]));
    }
  }
  // Where a point lies against each side: turn(side's start, side's end, x), >= 0 inside.
  void turns(const double* x, double* out) const {
    for (int i = 0; i < 3; ++i) out[i] = turn(t[i], t[(i + 1) % 3], x);
  }
};

// Whether segment a-b comes within distance `margin` of triangle T, given both ends' turns
// against T's sides (Sides::turns).
bool meets(const double* a_turns, const double* b_turns, const Sides& sides, double margin) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double slack = margin * sides.length[i];
    const double fa = a_turns[i] + slack, fb = b_turns[i] + slack;  // >= 0: inside this side
    if (fa < 0 && fb < 0) return false;
    if (fa < 0) lo = std::max(lo, fa / (fa - fb));
    if (fb < 0) hi = std::min(hi, fa / (fa - fb));
  }
  return lo <= hi;
}

// Whether a triangle lies wholly beyond one side of T, given its corners' turns against T's sides
// (Sides::turns): then it does not overlap T.
bool beyond_a_side(const double (&turns)[3][3]) {
  for (int i = 0; i < 3; ++i)
    if (turns[0][i] < 0 && turns[1][i] < 0 && turns[2][i] < 0) return true;
  return false;
}

// The corners of a triangle's overlap with T: its corners inside T, where its sides cross T's, and
// T's corners inside it (the overlap of two triangles is the convex polygon of these). q: its
// corners as (u, v, height); area: twice its area in T's plane (> 0); turns: its corners' turns
// against T's sides (Sides::turns). Calls reach(x, height) with each as (u, v) and the height of
// the triangle's plane there, linear along its sides and over it. False where they do not overlap.
template <typename Reach>
bool overlap_corners(const double* q, double area, const double (&turns)[3][3], const double (*t)[3], Reach&& reach) {
  bool any = false;
  for (int j = 0; j < 3; ++j) {
    const double *a = q + 3 * j, *b = q + 3 * ((j + 1) % 3);
    const double *ta = turns[j], *tb = turns[(j + 1) % 3];
    if (ta[0] >= 0 && ta[1] >= 0 && ta[2] >= 0) reach(a, std::abs(a[2])), any = true;
    for (int i = 0; i < 3; ++i) {
      if ((ta[i] >= 0) == (tb[i] >= 0)) continue;
      const double s = ta[i] / (ta[i] - tb[i]);  // where a -> b crosses the line of T's side i
      const int k = (i + 1) % 3, m = (i + 2) % 3;  // inside T's other sides there (turns are linear)
      if (ta[k] + s * (tb[k] - ta[k]) < 0 || ta[m] + s * (tb[m] - ta[m]) < 0) continue;
      const double x[3] = {a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])};
      reach(x, std::abs(x[2])), any = true;
    }
  }
  for (int i = 0; i < 3; ++i) {
    const double w0 = turn(q + 3, q + 6, t[i]), w1 = turn(q + 6, q, t[i]), w2 = turn(q, q + 3, t[i]);
    if (w0 >= 0 && w1 >= 0 && w2 >= 0) reach(t[i], std::abs((w0 * q[2] + w1 * q[5] + w2 * q[8]) / area)), any = true;
  }
  return any;
}

using Side = BeneathScratch::Side;

// The slots of the tree's triangles whose boxes meet [lo, hi], into scratch.slots; false where
// there are more than max_candidates.
bool collect_candidates(const TriangleBvh& tree, const double* lo, const double* hi, int32_t max_candidates,
                        BeneathScratch& scratch) {
  std::vector<int32_t>& stack = scratch.stack;
  std::vector<int32_t>& slots = scratch.slots;
  stack.assign(1, 0);
  slots.clear();
  while (!stack.empty()) {
    const TriangleBvh::Node& node = tree.node(stack.back());
    const int32_t i = stack.back();
    stack.pop_back();
    bool overlaps = true;
    for (int k = 0; k < 3; ++k) overlaps = overlaps && node.lo[k] <= hi[k] && node.hi[k] >= lo[k];
    if (!overlaps) continue;
    if (node.count == 0) {
      stack.push_back(i + 1), stack.push_back(node.first);
      continue;
    }
    for (int32_t s = node.first; s < node.first + node.count; ++s) {
      const double* c = tree.slot_corners(s);  // a leaf's triangle whose own box misses the range cannot count
      bool meets = true;
      for (int k = 0; k < 3; ++k)
        meets = meets && std::min({c[k], c[3 + k], c[6 + k]}) <= hi[k] && std::max({c[k], c[3 + k], c[6 + k]}) >= lo[k];
      if (meets) slots.push_back(s);
    }
    if (int32_t(slots.size()) > max_candidates) return false;
  }
  return true;
}

// Whether every side is matched by sides in the opposite direction (their signs cancel): then no
// boundary of U crosses T. A few sides are sorted; many (a piece over hundreds of triangles) have
// their signs summed in a hash table of the scratch's.
bool paired(BeneathScratch& scratch) {
  std::vector<Side>& sides = scratch.sides;
  if (sides.size() <= kSortedSides) {
    std::sort(sides.begin(), sides.end(),
              [](const Side& x, const Side& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    for (size_t i = 0; i < sides.size();) {
      size_t j = i;
      int32_t net = 0;
      for (; j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b; ++j) net += sides[j].sign;
      if (net != 0) return false;
      i = j;
    }
    return true;
  }
  size_t size = 16;
  while (size < 2 * sides.size()) size *= 2;
  constexpr uint64_t kEmpty = ~uint64_t(0);
  scratch.keys.assign(size, kEmpty);
  scratch.nets.resize(size);
  for (const Side& side : sides) {
    const uint64_t key = uint64_t(uint32_t(side.a)) << 32 | uint32_t(side.b);
    size_t i = size_t((key * 0x9E3779B97F4A7C15ull) >> 32) & (size - 1);
    while (scratch.keys[i] != kEmpty && scratch.keys[i] != key) i = (i + 1) & (size - 1);
    if (scratch.keys[i] == kEmpty) scratch.keys[i] = key, scratch.nets[i] = 0;
    scratch.nets[i] += side.sign;
  }
  for (size_t i = 0; i < size; ++i)
    if (scratch.keys[i] != kEmpty && scratch.nets[i] != 0) return false;
  return true;
}

// T in its own plane: the frame, T's corners as (u, v, 0) and the figures every candidate's test
// reads. False for a degenerate T.
struct Flat {
  Frame frame;
  double t[3][3];
  double twice_area, l1;
  double magnitude;  // the largest coordinate's magnitude of T's corners
  bool set(const double p[3][3]) {
    magnitude = 0.0;
    for (int j = 0; j < 3; ++j) magnitude = std::max({magnitude, std::abs(p[j][0]), std::abs(p[j][1]), std::abs(p[j][2])});
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) frame.origin[k] = p[0][k], e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
    cross(e1, e2, frame.n);
    twice_area = std::sqrt(dot(frame.n, frame.n)), l1 = std::sqrt(dot(e1, e1));
    if (!(twice_area > 0 && l1 > 0)) return false;
    for (int k = 0; k < 3; ++k) frame.n[k] /= twice_area, frame.u[k] = e1[k] / l1;
    cross(frame.n, frame.u, frame.v);
    for (int j = 0; j < 3; ++j) frame.project(p[j], t[j]);
    return true;
  }
};

// Triangle f's corner coordinates copied into buffer (9 values), for candidates listed by id.
const double* corners_of(const Surface& to, int32_t f, double* buffer) {
  const int32_t* t = &to.triangles()[3 * size_t(f)];
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) buffer[3 * j + k] = to.positions()[3 * size_t(t[j]) + size_t(k)];
  return buffer;
}

// The candidates of B as the search tree's slots, or as triangle ids of `to` (their corners
// copied into `buffer`).
struct SlotCandidates {
  const TriangleBvh& tree;
  const std::vector<int32_t>& slots;
  size_t size() const { return slots.size(); }
  const double* corners(size_t i, double* /*buffer*/) const { return tree.slot_corners(slots[i]); }
  int32_t triangle(size_t i) const { return tree.slot_triangle(slots[i]); }
  static constexpr bool kGrows = false;  // the list is whole from the start
  void across(size_t, int) const {}
  bool overflowed() const { return false; }
};
struct ListedCandidates {
  const Surface& to;
  const std::vector<int32_t>& ids;
  size_t size() const { return ids.size(); }
  const double* corners(size_t i, double* buffer) const { return corners_of(to, ids[i], buffer); }
  int32_t triangle(size_t i) const { return ids[i]; }
  static constexpr bool kGrows = false;
  void across(size_t, int) const {}
  bool overflowed() const { return false; }
};

// The candidates as a chain grown from a few triangles of `to`: each side of a triangle kept in U
// that meets T adds the triangle across it (each met once a call).
struct GrownCandidates {
  const Surface& to;
  const TriangleWalk& walk;
  const int32_t max_candidates;
  BeneathScratch& scratch;
  std::vector<int32_t>& ids;
  bool over = false;  // more than max_candidates met
  static constexpr bool kGrows = true;
  GrownCandidates(const Surface& to, const TriangleWalk& walk, const int32_t* start, int starts,
                  int32_t max_candidates, BeneathScratch& scratch)
      : to(to), walk(walk), max_candidates(max_candidates), scratch(scratch), ids(scratch.slots) {
    if (scratch.seen.size() != size_t(to.num_triangles()) || ++scratch.call == 0)
      scratch.seen.assign(size_t(to.num_triangles()), 0), scratch.call = 1;
    ids.clear();
    for (int i = 0; i < starts; ++i)
      if (start[i] >= 0) meet(start[i]);
  }
  size_t size() const { return ids.size(); }
  const double* corners(size_t i, double* buffer) const { return corners_of(to, ids[i], buffer); }
  int32_t triangle(size_t i) const { return ids[i]; }
  void meet(int32_t f) {
    if (f < 0 || scratch.seen[size_t(f)] == scratch.call) return;
    scratch.seen[size_t(f)] = scratch.call;
    if (int32_t(ids.size()) < max_candidates) {
      ids.push_back(f);
    } else {
      over = true;
    }
  }
  void across(size_t i, int side) { meet(walk.neighbour(ids[i], side)); }
  bool overflowed() const { return over; }
};

// The bound over the candidates (SlotCandidates or ListedCandidates). listed (projected_bound_over's
// bound): the margin is at least kRoundingMargin's and at most kMargin's, as large as keeps its
// reach within kMarginShare of the limit. at, when given: the (u, v)
// of T where the bound is reached.
template <typename Candidates>
double bound_over(const Flat& flat, const Surface& to, double limit, BeneathScratch& scratch, bool along_creases,
                  bool listed, double* at, Candidates&& candidates, bool* uncovered = nullptr) {
  const Frame& frame = flat.frame;
  const double(&t)[3][3] = flat.t;
  const double twice_area = flat.twice_area, l1 = flat.l1;
  const Sides t_sides(t);
  // The facing triangles over T give the bound, and those of their sides that come near T must
  // be shared by two of them in opposite directions (no boundary of U crosses T).
  // along_creases: coverage is decided over T shrunk by the margin (a boundary of U along T's
  // sides does not fail it), so it is tested at T's incentre, and a point of T outside the shrunk
  // one lies within margin x (farthest corner from the incentre) / inradius of a point inside it.
  const double la = std::hypot(t[2][0] - l1, t[2][1]), lb = std::hypot(t[2][0], t[2][1]), perimeter = la + lb + l1;
  const double incentre[2] = {(la * t[0][0] + lb * t[1][0] + l1 * t[2][0]) / perimeter,
                              (la * t[0][1] + lb * t[1][1] + l1 * t[2][1]) / perimeter};
  const double inradius = twice_area / perimeter;
  double farthest = 0.0;
  for (int j = 0; j < 3; ++j) farthest = std::max(farthest, std::hypot(t[j][0] - incentre[0], t[j][1] - incentre[1]));
  const double longest = std::max({l1, lb, la});
  const double margin =
      listed ? std::max(kRoundingMargin * (flat.magnitude + longest),
                        std::min(kMargin * longest, kMarginShare * limit * inradius / farthest))
             : kMargin * longest;
  if (along_creases && !(inradius > 2 * margin)) return kNoBound;
  const double t_lo[2] = {std::min(0.0, t[2][0]) - margin, -margin};
  const double t_hi[2] = {std::max(l1, t[2][0]) + margin, t[2][1] + margin};
  // Whether a point (u, v) lies within the margin of a corner of T.
  auto at_corner = [&](const double* x) {
    for (int j = 0; j < 3; ++j)
      if ((x[0] - t[j][0]) * (x[0] - t[j][0]) + (x[1] - t[j][1]) * (x[1] - t[j][1]) <= margin * margin) return true;
    return false;
  };
  std::vector<Side>& sides = scratch.sides;
  sides.clear();
  double bound = 0.0;
  bool covered = false;
  for (size_t i = 0; i < candidates.size(); ++i) {
    double buffer[9];
    const double* corners = candidates.corners(i, buffer);
    double q[9], d[3][3];  // the corners' (u, v, height), their heights only once over T
    for (int j = 0; j < 3; ++j) {
      frame.offset(corners + 3 * j, d[j]);
      q[3 * j] = dot(d[j], frame.u), q[3 * j + 1] = dot(d[j], frame.v);
    }
    bool apart = false;
    for (int k = 0; k < 2; ++k)
      apart = apart || std::max({q[k], q[3 + k], q[6 + k]}) < t_lo[k] || std::min({q[k], q[3 + k], q[6 + k]}) > t_hi[k];
    if (apart) continue;  // neither over T nor with a side near it
    for (int j = 0; j < 3; ++j) q[3 * j + 2] = dot(d[j], frame.n);
    double f1[3], f2[3], normal[3];
    for (int k = 0; k < 3; ++k) f1[k] = corners[3 + k] - corners[k], f2[k] = corners[6 + k] - corners[k];
    cross(f1, f2, normal);
    const double area = turn(q, q + 3, q + 6);
    if (!(area > kFacing * std::sqrt(dot(normal, normal)))) continue;
    double turns[3][3];
    for (int j = 0; j < 3; ++j) t_sides.turns(q + 3 * j, turns[j]);
    // The highest height of the triangle's plane over its overlap with T, at one of the overlap's
    // corners; none looked for where it lies beyond a side of T, or where its corners' heights
    // cannot raise the bound once T is known covered (a quarter of a report's candidates).
    // along_creases: the distance to the triangle there where the height would exceed the limit
    // (never more than the height; convex over the overlap, so it peaks at one of its corners);
    // below it the height settles as well and costs no closest point.
    double own = 0.0, own_at[2] = {0.0, 0.0};
    const bool overlaps =
        !beyond_a_side(turns) && !(covered && std::max({std::abs(q[2]), std::abs(q[5]), std::abs(q[8])}) <= bound) &&
        overlap_corners(q, area, turns, t, [&](const double* x, double height) {
          const double value = along_creases && height > limit ? frame.distance(x, corners) : height;
          if (value > own) own = value, own_at[0] = x[0], own_at[1] = x[1];
        });
    // along_creases: a triangle beyond the limit is left out of U (any part of the chain bounds
    // what it covers; the sides it leaves unmatched fail the test below where they cross T)
    if (own > limit) {
      if (along_creases) continue;
      return kNoBound;
    }
    if (own >= bound && at != nullptr) at[0] = own_at[0], at[1] = own_at[1];
    bound = std::max(bound, own);
    if (overlaps && (!along_creases || (turn(q, q + 3, incentre) >= 0 && turn(q + 3, q + 6, incentre) >= 0 &&
                                                    turn(q + 6, q, incentre) >= 0)))
      covered = true;
    const int32_t* ids = &to.triangles()[3 * size_t(candidates.triangle(i))];
    for (int j = 0; j < 3; ++j) {
      const int32_t a = ids[j], b = ids[(j + 1) % 3];
      if (meets(turns[j], turns[(j + 1) % 3], t_sides, along_creases ? -margin : margin)) {
        sides.push_back(a < b ? Side{a, b, 1} : Side{b, a, -1});
        candidates.across(i, j);
      } else if (std::decay_t<Candidates>::kGrows && along_creases &&
                 (at_corner(q + 3 * j) || at_corner(q + 3 * ((j + 1) % 3)))) {
        candidates.across(i, j);  // around a corner of T on a vertex of B
      }
    }
  }
  if (candidates.overflowed()) return kNoBound;
  if (!covered) {
    if (uncovered != nullptr) *uncovered = true;
    return kNoBound;
  }
  if (!paired(scratch)) return kNoBound;
  if (along_creases) {
    bound += margin * farthest / inradius;
    if (bound > limit) return kNoBound;
  }
  return bound;
}

}  // namespace

double projected_bound(const double p[3][3], const Surface& to, double limit, int32_t max_candidates,
                       BeneathScratch& scratch, bool along_creases) {
  Flat flat;
  if (!flat.set(p)) return kNoBound;
  // B's triangles in T's box grown by the limit: nothing beyond it can bring a bound under it.
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min({p[0][k], p[1][k], p[2][k]}) - limit;
    hi[k] = std::max({p[0][k], p[1][k], p[2][k]}) + limit;
  }
  const TriangleBvh& tree = to.bvh();
  if (!collect_candidates(tree, lo, hi, max_candidates, scratch)) return kNoBound;
  return bound_over(flat, to, limit, scratch, along_creases, false, nullptr, SlotCandidates{tree, scratch.slots});
}

double projected_bound_around(const double p[3][3], const Surface& to, const TriangleWalk& walk, const int32_t* start,
                              int starts, double limit, int32_t max_candidates, BeneathScratch& scratch) {
  Flat flat;
  if (!flat.set(p)) return kNoBound;
  bool uncovered = false;
  const double bound = bound_over(flat, to, limit, scratch, true, false, nullptr,
                                  GrownCandidates(to, walk, start, starts, max_candidates, scratch), &uncovered);
  if (!uncovered) return bound;
  return projected_bound(p, to, limit, max_candidates, scratch, true);
}

double projected_bound_over(const double p[3][3], const Surface& to, const std::vector<int32_t>& triangles,
                            double limit, BeneathScratch& scratch, double reached[3]) {
  Flat flat;
  if (!flat.set(p)) return kNoBound;
  double at[2] = {0.0, 0.0};
  const double bound = bound_over(flat, to, limit, scratch, true, true, at, ListedCandidates{to, triangles});
  for (int k = 0; k < 3; ++k) reached[k] = flat.frame.origin[k] + at[0] * flat.frame.u[k] + at[1] * flat.frame.v[k];
  return bound;
}

}  // namespace topstoc
