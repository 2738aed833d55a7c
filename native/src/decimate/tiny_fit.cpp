#include "decimate/tiny_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "decimate/sparse_normal.hpp"
#include "distance/bounded_max.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/distance/bvh.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

namespace {

// Input vertices paired with the result: at most this many (every k-th vertex of a larger input).
constexpr int64_t kFitPoints = 20000;
// Input triangles the result's samples are paired with: at most this many (every k-th of a
// larger input; the gaps are far smaller than a tiny result's deviation, and a search structure
// over a million triangles cost more than the collapses).
constexpr int64_t kFitTriangles = 200000;
// The symmetric max that judges a round is bracketed to this relative width, with at most this
// many closest-point queries each way (the bracket stays valid when they run out).
constexpr double kMaxTolerance = 1e-2;
constexpr int64_t kMaxQueries = 2000000;
// The fit's brackets together: at most this many closest-point queries per input triangle (and
// kFitQueriesFloor in any case), every kTestedPerQuery triangles the queries measured (or the
// bounds beneath looked at) counting as one more (a query among a fan's slivers measures hundreds); then no further move is tried. The
// fits of the test meshes took 2-51 a triangle (Suzanne at 10 %: 159); fans of slivers 400-3,700
// (a cylinder of 256 segments with fanned caps, 2,560 triangles, at 10 %: 21 brackets, 9.5M, 10 s).
constexpr int64_t kFitQueriesPerTriangle = 300;
constexpr int64_t kFitQueriesFloor = 100000;
// One side of one bracket: at most this many per input triangle (kFitQueriesFloor / 2 in any
// case). The test meshes' sides took up to 4 (50 triangles measured); a fan's ran out at 2M
// queries or 32M triangles measured, unconverged, its upper bound hundreds of times its lower.
constexpr int64_t kSideQueriesPerTriangle = 8;
// A result whose pairs all lie this close to the input (normalised coordinates) lies on it:
// nothing to fit, and the max's bracket could not settle on surfaces that coincide.
constexpr double kOnTheInput = 1e-9;
// Times a move whose max grew is tried again with more corners held.
constexpr int32_t kHoldTries = 8;
// A vertex the fit took to the far point may go back halfway when the mean squared distance
// grows by at most this factor (back_off).
constexpr double kBackOffMean = 1.02;
// The shortest step toward the least-squares positions tried when the full one is refused.
constexpr double kSmallestStep = 0.25;
// Each unknown is pulled to where it stands with this share of the mean diagonal of the normal
// equations, so that a vertex few pairs see stays put.
constexpr double kStay = 1e-3;
// Results above kFitFaces (fit_large): the normal equations solved by conjugate gradients to
// this relative residual or this many iterations, and the max judged by one threshold walk a
// side of at most this many closest-point queries per result triangle (a walk that runs out
// refuses the move).
constexpr double kSolveTolerance = 1e-6;
constexpr int32_t kSolveIterations = 200;
constexpr int64_t kLargeQueriesPerFace = 40;
// A distance before the move this close to the one after (relative) is the same, measured
// again at a point rebuilt from its barycentric weights.
constexpr double kSameDistance = 1e-9;
// And the corners of its triangles with a pair farther than this share of the max stay put.
constexpr double kNearMax = 0.5;
// Samples of each result triangle paired with the input, as barycentric weights.
constexpr double kSamples[7][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3}, {0.5, 0.5, 0.0}, {0.0, 0.5, 0.5}, {0.5, 0.0, 0.5},
                                   {0.6, 0.2, 0.2},             {0.2, 0.6, 0.2}, {0.2, 0.2, 0.6}};

// A point of the result, sum of b[j] times corner j of `face`, and where it should be.
struct Pair {
  int32_t face;
  double b[3], target[3], weight;
};

// Barycentric weights of p (a point of triangle a, b, c) in it; a degenerate triangle gives
// its first corner.
void barycentric(const double* p, const double* a, const double* b, const double* c, double* w) {
  double e0[3], e1[3], d[3];
  for (int i = 0; i < 3; ++i) e0[i] = b[i] - a[i], e1[i] = c[i] - a[i], d[i] = p[i] - a[i];
  auto dot = [](const double* x, const double* y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(d, e0), d21 = dot(d, e1);
  const double det = d00 * d11 - d01 * d01;
  if (!(det > 0)) {
    w[0] = 1.0, w[1] = w[2] = 0.0;
    return;
  }
  w[1] = std::clamp((d11 * d20 - d01 * d21) / det, 0.0, 1.0);
  w[2] = std::clamp((d00 * d21 - d01 * d20) / det, 0.0, 1.0 - w[1]);
  w[0] = 1.0 - w[1] - w[2];
}

class Fit {
 public:
  Fit(const Mesh& mesh, Collapser& collapser, bool boundaries, const Surface& input) : c_(collapser), input_(&input) {
    const std::vector<int32_t>& triangles = c_.triangles();
    // Every k-th input vertex in a triangle (isolated ones are no part of the surface).
    int32_t in_faces = 0;
    for (int32_t w = 0; w < mesh.num_vertices(); ++w) in_faces += mesh.in_faces(w);
    const int32_t stride = int32_t(std::max<int64_t>(1, (in_faces + kFitPoints - 1) / kFitPoints));
    for (int32_t w = 0, seen = 0; w < mesh.num_vertices(); ++w)
      if (mesh.in_faces(w) && seen++ % stride == 0) points_.push_back(w);
    for (int32_t t = 0; t < int32_t(triangles.size() / 3); ++t)
      if (c_.face_alive(t)) faces_.insert(faces_.end(), &triangles[3 * size_t(t)], &triangles[3 * size_t(t) + 3]);
    large_ = int64_t(faces_.size() / 3) > kFitFaces;
    unknown_.assign(c_.vertices(), -1);
    for (int32_t v : faces_)
      if ((boundaries ? c_.fittable(v) : c_.is_free(v)) && unknown_[v] < 0) unknown_[v] = int32_t(free_.size()), free_.push_back(v);
    std::sort(free_.begin(), free_.end());  // vertex order: moves are tried in it
    for (size_t i = 0; i < free_.size(); ++i) unknown_[free_[i]] = int32_t(i);
    // The live vertices numbered apart, so that the surfaces measured hold only them.
    std::vector<int32_t> compact(c_.vertices(), -1);
    for (int32_t v : faces_)
      if (compact[v] < 0) compact[v] = int32_t(live_.size()), live_.push_back(v);
    for (int32_t v : faces_) live_faces_.push_back(compact[v]);
  }

  bool empty() const { return free_.empty() || faces_.empty() || points_.empty(); }

  // The fit's queries (kFitQueriesPerTriangle), and whether its brackets so far spent them.
  int64_t query_budget() const {
    return std::max(kFitQueriesFloor, kFitQueriesPerTriangle * int64_t(input_->num_triangles()));
  }
  bool spent() const { return queries_ > query_budget(); }
  // One side of a full bracket (kSideQueriesPerTriangle), within half the fit's queries.
  int64_t side_budget() const {
    const int64_t side = std::max(kFitQueriesFloor / 2, kSideQueriesPerTriangle * int64_t(input_->num_triangles()));
    return std::min({kMaxQueries, query_budget() / 2, side});
  }
  int64_t queries() const { return queries_; }
  int32_t brackets() const { return brackets_; }

  // A bracket on the symmetric Hausdorff max between the result and (the fitted part of) the
  // input, over every point of both surfaces: the pairs only sample it, and a round that lowers
  // their mean can still lift the surface away between the samples.
  struct Bracket {
    double lower = 0.0, upper = 0.0;
    int32_t face = -1;  // the result triangle nearest the point where `lower` was found
    double point[3] = {0, 0, 0};  // that point
    bool converged = true;  // false when a side ran out of queries (upper then decides nothing)
    bool on_result = false;  // whether `point` lies on the result (else on the input)
    bool input_passed = false, result_passed = false;  // (lean) the sides found no farther point
  };
  // at: the result's vertex positions (positions()). threshold >= 0: only whether the max
  // exceeds it is decided (bounded_max.hpp), cheaper, and the second side is skipped once the
  // first exceeds it; without, the two sides run side by side where a core is free (each side's
  // bracket is the same on any thread).
  // lean (with a threshold): the result side over the triangles the last apply moved only, the
  // input side by input_side, at most kLargeQueriesPerFace queries per result triangle a side
  // (converged false when they run out).
  // input_passed, result_passed (lean): that side already passed at a threshold no higher, the
  // result where it was: it is not walked again.
  Bracket symmetric_max(std::vector<double> at, double threshold = -1.0, bool lean = false, bool input_passed = false,
                        bool result_passed = false) {
    const Surface result(std::move(at), live_faces_);
    MaxBracket there, back;
    const int64_t budget = lean ? kLargeQueriesPerFace * int64_t(faces_.size() / 3) : side_budget();
    // lean: only the result triangles the last apply moved (the others stood where the max
    // before the move was measured, and a far point there only raised the threshold again).
    auto measure_there = [&] {
      there = lean ? bound_max_over_triangles(result, moved_faces_, *input_, threshold, kMaxTolerance, budget)
                   : bound_max_distance_by_tree(result, *input_, kMaxTolerance, budget, threshold, lean);
    };
    auto measure_back = [&] {
      back = bound_max_distance_by_tree(*input_, result, kMaxTolerance, budget, threshold, lean);
    };
    // lean: the cheapest check first: the input vertices (listing every far point), then the
    // moved result triangles, then the input triangles.
    auto result_side = [&] {
      if (!result_passed) measure_there();
      return result_passed = !(there.lower > threshold) && there.converged;
    };
    if (lean) {
      if (!input_passed) {
        back = input_side(result, threshold, budget, result_side);
        input_passed = !(back.lower > threshold) && back.converged && result_passed;
      } else {
        result_side();
      }
    } else if (threshold >= 0.0) {
      measure_there();
      if (!(there.lower > threshold)) measure_back();
    } else {
      result.bvh(), input_->bvh();  // built before the sides share them
      const FreeCoresNow team;
      parallel_invoke(true, measure_there, measure_back);
    }
    queries_ += there.queries + back.queries + (there.tested + back.tested) / kTestedPerQuery;
    ++brackets_;
    const MaxBracket& far = there.lower >= back.lower ? there : back;
    Bracket b{far.lower, std::max(there.upper, back.upper), result.bvh().closest(far.lower_point, -1).triangle,
              {0, 0, 0}, there.converged && back.converged, &far == &there};
    for (int k = 0; k < 3; ++k) b.point[k] = far.lower_point[k];
    b.input_passed = lean && input_passed, b.result_passed = lean && result_passed;
    return b;
  }

  // Whether the input lies farther than threshold from `result` anywhere (a bracket whose lower
  // exceeds it where it does): each input vertex measured, then each input triangle bounded by
  // its corners' largest distance to one result triangle, the nearest to one of its corners
  // (a distance to a triangle is convex, so over the input triangle it peaks at a corner); the
  // few triangles that leaves above the threshold are bracketed (bounded_max.hpp).
  // far_faces_: the result triangles nearest to the input vertices farther than threshold.
  // between: run once the vertices pass, before the triangles; false ends the walk there.
  template <class Between>
  MaxBracket input_side(const Surface& result, double threshold, int64_t budget, Between&& between) {
    const std::vector<double>& at = input_->positions();
    const std::vector<int32_t>& triangles = input_->triangles();
    const std::vector<double>& corners = result.positions();
    std::vector<int32_t> nearest(size_t(input_->num_vertices()), -1);
    MaxBracket out;
    int32_t hint = -1;
    far_faces_.clear();
    for (int32_t v = 0; v < input_->num_vertices(); ++v) {
      if (!input_->used()[v]) continue;
      const ClosestHit hit = result.bvh().closest(&at[3 * size_t(v)], hint);
      hint = hit.slot, nearest[v] = hit.triangle, ++out.queries;
      if (hit.distance2 > threshold * threshold) far_faces_.push_back(hit.triangle);
      if (hit.distance2 > out.lower * out.lower) {
        out.lower = std::sqrt(hit.distance2);
        for (int i = 0; i < 3; ++i) out.lower_point[i] = at[3 * size_t(v) + i];
      }
    }
    if (out.lower > threshold) return out.upper = out.lower, out.converged = false, out;
    if (!between()) return out.upper = out.lower, out;
    std::vector<int32_t> open;
    const double limit2 = threshold * threshold;
    for (int32_t s = 0; s < input_->num_triangles(); ++s) {
      const int32_t* c = &triangles[3 * size_t(s)];
      bool settled = false;
      for (int j = 0; j < 3 && !settled; ++j) {
        const int32_t* t = &live_faces_[3 * size_t(nearest[c[j]])];
        double far2 = 0.0, point[3];
        for (int i = 0; i < 3; ++i)
          far2 = std::max(far2, closest_point_on_triangle(&at[3 * size_t(c[i])], &corners[3 * size_t(t[0])],
                                                          &corners[3 * size_t(t[1])], &corners[3 * size_t(t[2])], point));
        settled = far2 <= limit2;
      }
      if (!settled) open.push_back(s);
    }
    if (open.empty()) return out.upper = threshold, out;
    MaxBracket rest = bound_max_over_triangles(*input_, open, result, threshold, kMaxTolerance, budget);
    rest.queries += out.queries;
    return rest;
  }

  // The distance the result at `start` (positions()) had at the far point of b: there the same
  // point of the same triangle (b.face), on the input to the result's surface `before` (made
  // from start).
  double distance_before(const Bracket& b, const std::vector<double>& start, const Surface& before) const {
    if (!b.on_result) return std::sqrt(before.bvh().closest(b.point, -1).distance2);
    const int32_t* f = &live_faces_[3 * size_t(b.face)];
    double w[3], p[3] = {0, 0, 0};
    barycentric(b.point, corner(b.face, 0), corner(b.face, 1), corner(b.face, 2), w);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) p[i] += w[j] * start[3 * size_t(f[j]) + i];
    return std::sqrt(input_->bvh().closest(p, -1).distance2);
  }
  const std::vector<int32_t>& live_faces() const { return live_faces_; }

  // Holds the result triangles the last input_side found input vertices too far from; false
  // when there were none.
  bool hold_far_faces() {
    for (int32_t f : far_faces_) hold(f);
    return !far_faces_.empty();
  }

  // Keeps the corners of result triangle f where they stand in the moves that follow.
  void hold(int32_t f) {
    if (held_.empty()) held_.assign(c_.vertices(), 0);
    for (int j = 0; j < 3; ++j) held_[faces_[3 * size_t(f) + j]] = 1;
  }
  void release() { held_.clear(); }

  // Holds the corners of every result triangle with a pair farther than `limit` (as the last
  // pair_up found them): where the far points may lie the result stays as it was.
  void hold_far_pairs(double limit) {
    for (const Pair& pair : pairs_)
      if (distance2(pair) > limit * limit) hold(pair.face);
  }

  // The corner of result triangle f nearest p.
  int32_t nearest_corner(int32_t f, const double* p) const {
    int32_t best = -1;
    double nearest = std::numeric_limits<double>::infinity();
    for (int j = 0; j < 3; ++j) {
      const double* q = corner(f, j);
      const double d = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]);
      if (d < nearest) nearest = d, best = faces_[3 * size_t(f) + j];
    }
    return best;
  }

  // Moves free vertex v a share t of the way back to where it stood in `start` (positions());
  // undo() takes it back.
  bool move_back(int32_t v, const std::vector<double>& start, double t) {
    saved_.clear();
    const auto at = std::find(live_.begin(), live_.end(), v);
    if (unknown_[v] < 0 || at == live_.end()) return false;
    const double* was = &start[3 * size_t(at - live_.begin())];
    Saved s{v, {}, {}};
    double to[3];
    for (int i = 0; i < 3; ++i) {
      s.position[i] = c_.position(v)[i], s.world[i] = c_.world(v)[i];
      to[i] = s.position[i] + t * (was[i] - s.position[i]);
    }
    if (!c_.try_move(v, to)) return false;
    saved_.push_back(s);
    return true;
  }

  // The pairs of the current result and their weighted mean and largest squared distance.
  struct Error {
    double mean2 = 0.0, top2 = 0.0;
  };
  Error pair_up() {
    pairs_.clear();
    const std::vector<double> at_vertices = positions();
    const int32_t m = int32_t(faces_.size() / 3);
    const TriangleBvh result(at_vertices.data(), live_faces_.data(), m);
    const double point_weight = 1.0 / double(points_.size());
    int32_t hint = -1;
    for (int32_t w : points_) {
      const double* p = &input_->positions()[3 * size_t(w)];
      const ClosestHit hit = result.closest(p, hint);
      hint = hit.slot;
      Pair pair{hit.triangle, {}, {p[0], p[1], p[2]}, point_weight};
      barycentric(hit.point, corner(hit.triangle, 0), corner(hit.triangle, 1), corner(hit.triangle, 2), pair.b);
      pairs_.push_back(pair);
    }
    std::vector<double> area(m);
    double total = 0.0;
    for (int32_t f = 0; f < m; ++f) total += area[f] = twice_area(f);
    hint = -1;
    for (int32_t f = 0; f < m && total > 0; ++f)
      for (const auto& b : kSamples) {
        Pair pair{f, {b[0], b[1], b[2]}, {}, area[f] / (7.0 * total)};
        double s[3];
        at(pair, s);
        const ClosestHit hit = input_->bvh().closest(s, hint);
        hint = hit.slot;
        for (int i = 0; i < 3; ++i) pair.target[i] = hit.point[i];
        pairs_.push_back(pair);
      }
    Error error;
    for (const Pair& pair : pairs_) {
      const double d2 = distance2(pair);
      error.mean2 += pair.weight * d2;
      error.top2 = std::max(error.top2, d2);
    }
    return error;
  }

  // The pairs' terms of the normal equations: add(row, column, value) for the matrix, the
  // right-hand sides (three a row) into rhs; the dense and the sparse solve share it.
  template <class Add>
  void add_pairs(Add add, std::vector<double>& rhs) const {
    for (const Pair& pair : pairs_) {
      const int32_t* c = &faces_[3 * size_t(pair.face)];
      double fixed[3] = {pair.target[0], pair.target[1], pair.target[2]};
      for (int j = 0; j < 3; ++j)
        if (unknown_[c[j]] < 0)
          for (int i = 0; i < 3; ++i) fixed[i] -= pair.b[j] * c_.position(c[j])[i];
      for (int j = 0; j < 3; ++j) {
        const int32_t r = unknown_[c[j]];
        if (r < 0 || pair.b[j] == 0.0) continue;
        for (int l = 0; l < 3; ++l)
          if (unknown_[c[l]] >= 0) add(r, unknown_[c[l]], pair.weight * pair.b[j] * pair.b[l]);
        for (int i = 0; i < 3; ++i) rhs[3 * size_t(r) + i] += pair.weight * pair.b[j] * fixed[i];
      }
    }
  }

  // The least-squares positions of the free vertices for the current pairs; false when the
  // normal equations are singular.
  bool solve(std::vector<double>& x) const {
    if (large_) return solve_sparse(x);
    const size_t k = free_.size();
    std::vector<double> a(k * k, 0.0), rhs(3 * k, 0.0);
    add_pairs([&](int32_t r, int32_t l, double v) { a[size_t(r) * k + size_t(l)] += v; }, rhs);
    double trace = 0.0;
    for (size_t r = 0; r < k; ++r) trace += a[r * k + r];
    const double stay = kStay * trace / double(k);
    if (!(stay > 0)) return false;
    for (size_t r = 0; r < k; ++r) {
      a[r * k + r] += stay;
      for (int i = 0; i < 3; ++i) rhs[3 * r + i] += stay * c_.position(free_[r])[i];
    }
    return cholesky_solve(a, k, rhs, x);
  }

  // The same for a large result: the normal equations' non-zeros only, by conjugate gradients
  // from where the vertices stand.
  bool solve_sparse(std::vector<double>& x) const {
    const int32_t k = int32_t(free_.size());
    SparseNormal a(faces_, unknown_, k);
    std::vector<double> rhs(3 * size_t(k), 0.0);
    add_pairs([&](int32_t r, int32_t l, double v) { a.add(r, l, v); }, rhs);
    double trace = 0.0;
    for (int32_t r = 0; r < k; ++r) trace += a.diagonal(r);
    const double stay = kStay * trace / double(k);
    if (!(stay > 0)) return false;
    x.assign(3 * size_t(k), 0.0);
    for (int32_t r = 0; r < k; ++r) {
      a.add(r, r, stay);
      for (int i = 0; i < 3; ++i) {
        rhs[3 * size_t(r) + i] += stay * c_.position(free_[r])[i];
        x[3 * size_t(r) + i] = c_.position(free_[r])[i];
      }
    }
    a.solve(rhs, x, kSolveTolerance, kSolveIterations);
    return true;
  }

  bool large() const { return large_; }

  // The positions a step (0 to 1) of the way from where the free vertices stand to x.
  std::vector<double> toward(const std::vector<double>& x, double step) const {
    std::vector<double> y(x.size());
    for (size_t r = 0; r < free_.size(); ++r)
      for (int i = 0; i < 3; ++i) {
        const double now = c_.position(free_[r])[i];
        y[3 * r + i] = step == 1.0 ? x[3 * r + i] : now + step * (x[3 * r + i] - now);
      }
    return y;
  }

  // Moves each free vertex to x where its triangles allow it; returns the old states.
  int32_t apply(const std::vector<double>& x) {
    saved_.clear();
    int32_t moved = 0;
    for (size_t r = 0; r < free_.size(); ++r) {
      const int32_t v = free_[r];
      if (!held_.empty() && held_[v]) continue;
      Saved s{v, {}, {}};
      for (int i = 0; i < 3; ++i) s.position[i] = c_.position(v)[i], s.world[i] = c_.world(v)[i];
      if (c_.try_move(v, &x[3 * r])) saved_.push_back(s), ++moved;
    }
    list_moved_faces();
    return moved;
  }

  // The result triangles with a corner among the vertices the last apply moved.
  void list_moved_faces() {
    std::vector<uint8_t> moved(c_.vertices(), 0);
    for (const Saved& s : saved_) moved[s.v] = 1;
    moved_faces_.clear();
    for (int32_t f = 0; f < int32_t(faces_.size() / 3); ++f) {
      const int32_t* c = &faces_[3 * size_t(f)];
      if (moved[c[0]] || moved[c[1]] || moved[c[2]]) moved_faces_.push_back(f);
    }
  }

  void undo() {
    for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) c_.restore(it->v, it->position, it->world);
  }

  // The positions of the result's live vertices, in live_ order (live_faces_ index them).
  std::vector<double> positions() const {
    std::vector<double> at(3 * live_.size());
    for (size_t i = 0; i < live_.size(); ++i)
      for (int k = 0; k < 3; ++k) at[3 * i + k] = c_.position(live_[i])[k];
    return at;
  }

 private:
  struct Saved {
    int32_t v;
    double position[3], world[3];
  };
  const double* corner(int32_t f, int j) const { return c_.position(faces_[3 * size_t(f) + j]); }
  double twice_area(int32_t f) const {
    const double *a = corner(f, 0), *b = corner(f, 1), *c = corner(f, 2);
    double u[3], w[3];
    for (int i = 0; i < 3; ++i) u[i] = b[i] - a[i], w[i] = c[i] - a[i];
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    return std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  void at(const Pair& pair, double* s) const {
    for (int i = 0; i < 3; ++i)
      s[i] = pair.b[0] * corner(pair.face, 0)[i] + pair.b[1] * corner(pair.face, 1)[i] + pair.b[2] * corner(pair.face, 2)[i];
  }
  double distance2(const Pair& pair) const {
    double s[3];
    at(pair, s);
    return (s[0] - pair.target[0]) * (s[0] - pair.target[0]) + (s[1] - pair.target[1]) * (s[1] - pair.target[1]) +
           (s[2] - pair.target[2]) * (s[2] - pair.target[2]);
  }
  // Solves A X = B for a symmetric positive definite A (k by k) and three right-hand sides.
  static bool cholesky_solve(std::vector<double>& a, size_t k, const std::vector<double>& b, std::vector<double>& x) {
    for (size_t j = 0; j < k; ++j) {
      double d = a[j * k + j];
      for (size_t l = 0; l < j; ++l) d -= a[j * k + l] * a[j * k + l];
      if (!(d > 0)) return false;
      a[j * k + j] = std::sqrt(d);
      for (size_t r = j + 1; r < k; ++r) {
        double s = a[r * k + j];
        for (size_t l = 0; l < j; ++l) s -= a[r * k + l] * a[j * k + l];
        a[r * k + j] = s / a[j * k + j];
      }
    }
    x = b;
    for (int i = 0; i < 3; ++i) {
      for (size_t r = 0; r < k; ++r) {  // L y = b
        double s = x[3 * r + i];
        for (size_t l = 0; l < r; ++l) s -= a[r * k + l] * x[3 * l + i];
        x[3 * r + i] = s / a[r * k + r];
      }
      for (size_t r = k; r-- > 0;) {  // Lᵀ x = y
        double s = x[3 * r + i];
        for (size_t l = r + 1; l < k; ++l) s -= a[l * k + r] * x[3 * l + i];
        x[3 * r + i] = s / a[r * k + r];
      }
    }
    return true;
  }

  Collapser& c_;
  const Surface* input_;  // normalised input positions and (some of) its triangles
  std::vector<int32_t> points_;   // the input vertices paired with the result
  std::vector<int32_t> faces_;    // 3 vertex ids per live triangle
  std::vector<int32_t> live_;        // the vertices of live triangles, in first-use order
  std::vector<int32_t> live_faces_;  // faces_ with each vertex's index in live_
  std::vector<int32_t> free_;     // the unknowns' vertices
  std::vector<int32_t> unknown_;  // per vertex: its unknown, or -1 (fixed)
  std::vector<Pair> pairs_;
  std::vector<Saved> saved_;
  std::vector<uint8_t> held_;  // per vertex: 1 where the moves leave it (empty: none held)
  bool large_ = false;         // above kFitFaces triangles (solve_sparse, lean max walks)
  std::vector<int32_t> far_faces_;  // input_side's far points' result triangles
  std::vector<int32_t> moved_faces_;  // result triangles with a corner the last apply moved
  int64_t queries_ = 0;               // closest-point queries of the brackets so far
  int32_t brackets_ = 0;              // symmetric_max calls so far
};

}  // namespace

int64_t fit_input_step(const Mesh& mesh) {
  return std::max<int64_t>(1, (int64_t(mesh.num_faces()) + kFitTriangles - 1) / kFitTriangles);
}

namespace {

// After the rounds: while the far point is at a vertex the fit moved (the nearest corner of the
// triangle holding it), that vertex goes halfway back to where the collapses left it, kept when
// the max falls for a mean squared distance at most kBackOffMean higher (lilium at 2 %: a
// round that lowered the max moved another vertex out to be the new far one).
void back_off(Fit& fit, const std::vector<double>& start, Fit::Error& error) {
  if (fit.spent()) return;
  Fit::Bracket now = fit.symmetric_max(fit.positions());
  for (int32_t tries = 0; tries < kHoldTries && !fit.spent(); ++tries) {
    if (!fit.move_back(fit.nearest_corner(now.face, now.point), start, 0.5)) return;
    const auto next = fit.pair_up();
    if (next.mean2 <= kBackOffMean * error.mean2 && !(fit.symmetric_max(fit.positions(), now.lower).lower > now.lower)) {
      const auto next_max = fit.symmetric_max(fit.positions());
      if (next_max.upper < now.lower) {
        now = next_max, error = next;
        continue;
      }
    }
    fit.undo();
    fit.pair_up();
    return;
  }
}

// A result above kFitFaces: one round, judged against known_max (a distance the symmetric max
// attains before the move) by one lean threshold walk a side instead of two full brackets; the
// result side walks only the moved triangles (the others are as they were, no farther than the
// max before). No pairing after the move: the walks alone decide (a second pairing cost as much
// as the input side's walk, and its test refused moves the walks keep).
// Where a walk finds the surfaces farther apart than known_max: when the result stood as far
// there before the move (up to kSameDistance), that distance with the brackets' tolerance
// (kMaxTolerance, the slack the smaller results' check allows too) is the new known max and
// the walk runs again; else the
// corners of the result triangle there are held and the move tried again (a few times), then
// at half the step.
TinyFit fit_large(Fit& fit, const Fit::Error& error, double known_max) {
  TinyFit out;
  out.before2 = out.after2 = error.mean2;
  std::vector<double> x;
  if (!fit.solve(x)) return out;
  const std::vector<double> start = fit.positions();
  const Surface before(start, fit.live_faces());
  for (double step = 1.0; step >= kSmallestStep; step *= 0.5) {
    fit.release();
    // Pairs near the max before the move hold their triangles.
    fit.hold_far_pairs(kNearMax * known_max);
    for (int32_t tries = 0; tries < kHoldTries; ++tries) {
      if (fit.apply(fit.toward(x, step)) == 0) return out;
      auto walk = fit.symmetric_max(fit.positions(), known_max, true);
      for (int32_t raised = 0; raised < kHoldTries && walk.lower > known_max; ++raised) {
        const double was = fit.distance_before(walk, start, before);
        if (!(was >= walk.lower * (1.0 - kSameDistance))) break;
        known_max = (1.0 + kMaxTolerance) * std::max(was, walk.lower);
        walk = fit.symmetric_max(fit.positions(), known_max, true, walk.input_passed, walk.result_passed);
      }
      const bool farther = walk.lower > known_max;
      if (!farther && walk.converged) {
        out.rounds = 1;
        return out;
      }
      fit.undo();
      if (!farther) return out;  // the walk ran out of queries: nothing to hold
      if (walk.on_result || !fit.hold_far_faces()) fit.hold(walk.face);
    }
    fit.undo();
  }
  return out;
}

// What a move's max may reach: the bracket's upper bound, or where a side ran out of queries (a
// fan's slivers: the upper then hundreds of times the lower, and no move refused) the farthest
// point found, within the brackets' tolerance.
double ceiling(const Fit::Bracket& max) {
  return max.converged ? max.upper : std::min(max.upper, (1.0 + kMaxTolerance) * max.lower);
}

}  // namespace

TinyFit fit_tiny(const Mesh& mesh, Collapser& collapser, int32_t rounds, bool boundaries, const Surface& input,
                 double known_max) {
  TinyFit out;
  Fit fit(mesh, collapser, boundaries, input);
  if (fit.empty()) return out;
  auto error = fit.pair_up();
  if (error.top2 <= kOnTheInput * kOnTheInput) return out;
  if (fit.large()) return known_max > 0.0 ? fit_large(fit, error, known_max) : out;
  // The max before any move, measured only once a move's pairs pass (when none does it is not
  // needed, and it is the fit's dearest step): from the positions kept here, the same bracket.
  const std::vector<double> start = fit.positions();
  std::optional<Fit::Bracket> max;
  auto max_so_far = [&]() -> const Fit::Bracket& {
    if (!max) max = fit.symmetric_max(start);
    return *max;
  };
  out.before2 = out.after2 = error.mean2;
  std::vector<double> x;
  // A move is kept when the pairs' mean fell, their largest distance and the surfaces' max did
  // not grow. When only the max grew, the corners of the result triangle nearest to where it
  // grew are held and the move tried again (a few times); then at half the step, a quarter.
  // The last round's moves need only be judged against the max (no later round compares with
  // theirs): its bracket decides only whether the max grew.
  auto kept = [&](double step, bool last) {
    if (fit.spent()) return false;
    fit.release();
    for (int32_t tries = 0; tries < kHoldTries; ++tries) {
      if (fit.apply(fit.toward(x, step)) == 0) return false;
      const auto next = fit.pair_up();
      if (!(next.mean2 < error.mean2 && next.top2 <= error.top2)) break;
      const double upper = ceiling(max_so_far());
      const auto next_max = fit.symmetric_max(fit.positions(), last ? upper : -1.0);
      if (next_max.lower <= upper) {
        error = next, max = next_max;
        return true;
      }
      fit.undo();
      if (fit.spent()) return false;
      fit.hold(next_max.face);
    }
    fit.undo();
    return false;
  };
  for (int32_t round = 0; round < rounds && fit.solve(x); ++round) {
    bool moved = false;
    for (double step = 1.0; step >= kSmallestStep && !moved; step *= 0.5) moved = kept(step, round + 1 == rounds);
    if (!moved) break;
    out.after2 = error.mean2;
    ++out.rounds;
  }
  // Results fitted in several rounds only (a middle result's far point moved less, for more
  // of the fit's time).
  if (rounds > 1 && out.rounds > 0) {
    back_off(fit, start, error);
    out.after2 = error.mean2;
  }
  out.queries = fit.queries();
  out.brackets = fit.brackets();
  return out;
}

}  // namespace topstoc
