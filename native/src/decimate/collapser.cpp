#include "decimate/collapser.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/core/progress.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>


namespace topstoc {

namespace {

// The most triangles an edge collapsed along a non-manifold curve may have (more stay).
constexpr int32_t kMaxSheets = 8;

// A triangle whose normal turns by less than about 1e-4 radians keeps its plane (squared sine).
constexpr double kFlatTurn2 = 1e-8;

// True when a triangle with |n|² = twice_area2 and squared edge lengths summing to `edges` has a
// shape quality (Collapser::shape) below sqrt(shape2): without roots or divisions.
bool thinner(double twice_area2, double edges, double shape2) {
  return !(12.0 * twice_area2 >= shape2 * edges * edges) || edges == 0.0;
}

// Whether normals a and n (squared lengths a2, n2 > 0) differ by more than a flat star allows.
bool apart(const double* a, double a2, const double* n, double n2) {
  const double dot = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
  return !(dot > 0.0) || dot * dot < (1.0 - kFlatTurn2) * a2 * n2;
}

}  // namespace

Collapser::Collapser(std::vector<int32_t>& triangles, std::vector<int32_t>& corner_source, CollapseSetup setup)
    : tri_(&triangles), corner_source_(&corner_source), s_(std::move(setup)),
      heap_(static_cast<int32_t>(s_.weight.size())) {
  const int32_t n = static_cast<int32_t>(s_.weight.size());
  const size_t m = tri_->size() / 3;
  count_.assign(s_.quota.size(), 0);
  alive_vertices_ = n;
  alive_faces_ = static_cast<int32_t>(m);
  for (int32_t b : s_.bin) ++count_[b];
  begin_.assign(n, 0);
  size_.assign(n, 0);
  capacity_.assign(n, 0);
  for (int32_t v : *tri_) ++capacity_[v];
  int32_t offset = 0;
  for (int32_t v = 0; v < n; ++v) {
    begin_[v] = offset;
    offset += capacity_[v];
  }
  pool_.reserve(size_t(offset) + size_t(offset) / 2);
  pool_.resize(offset);
  for (size_t t = 0; t < m; ++t)
    for (int j = 0; j < 3; ++j) {
      const int32_t v = (*tri_)[3 * t + j];
      pool_[begin_[v] + size_[v]++] = int32_t(t);
    }
  alive_face_.assign(m, 1);
  lone_ = lone_corners(*tri_, size_t(n));
  for (int32_t v = 0; v < n && !tracking_floors_; ++v) tracking_floors_ = size_[v] > kWideFan;
  if (tracking_floors_) {
    floor_bound_.assign(n, Shared<double>());
    floor_witness_.assign(n, Shared<int32_t>());
    flat_star_.assign(n, Shared<int8_t>());
    flat_reference_.assign(n, Shared<int32_t>());
    changed_at_.assign(n, 0);
    kept_costs_of_.assign(n, -1);
    for (int32_t v = 0; v < n; ++v)
      if (size_[v] > kWideFan) kept_costs_of_[v] = int32_t(kept_costs_.size()), kept_costs_.emplace_back();
    beside_.assign(kept_costs_.size(), 0);
  }
  dirty_.assign(n, 0);
  placed_.assign(n, 0);
  merged_into_.assign(n, -1);
  target_.assign(n, -1);
  waiting_.assign(n, 0);
  settled_.assign(n, 0);
  merged_from_.assign(n, -1);
  set_up_spans();
  fit_threads();
  // Every vertex's cheapest collapse, each edge evaluated once (from its lower end) where it
  // costs the same both ways. A thread owns the lower ends it evaluates; what it finds for the
  // higher ends is merged after each block of kSetupBlock vertices, so the offers never hold
  // more than a block's edges (all of them were about 150 bytes a vertex at the collapser's
  // peak). The cheapest by (cost, id) does not depend on the order.
  std::vector<double> best_cost(n, 0.0);
  auto better = [&](int32_t u, int32_t v, double c) {
    return target_[u] < 0 || c < best_cost[u] || (c == best_cost[u] && v < target_[u]);
  };
  const int threads = scratch_.size();
  PerThread<std::vector<std::pair<int32_t, Best>>> found(threads);
  for (int32_t lo = 0, hi; lo < n; lo = hi) {
    hi = lo + std::min(kSetupBlock, n - lo);
    parallel_region(n >= 10000 ? threads : 1, [&](Team& team) {
      Scratch& scratch = scratch_.mine();
      auto& mine = found.mine();
      std::vector<int32_t> around;
      team.for_static(lo, hi, [&](int32_t u) {
        const bool u_queues = queues(u);
        neighbours(u, scratch, around);
        for (int32_t v : around) {
          if (v < u) continue;
          const bool v_queues = queues(v);
          const double uv = u_queues ? cost(u, v) : 0.0;
          if (u_queues && better(u, v, uv)) target_[u] = v, best_cost[u] = uv;
          if (v_queues) mine.push_back({v, {u, u_queues && free_pair(u, v) ? uv : cost(v, u)}});
        }
      });
    });
    for (int t = 0; t < threads; ++t) {
      for (const auto& [v, offer] : found[t])
        if (better(v, offer.target, offer.cost)) target_[v] = offer.target, best_cost[v] = offer.cost;
      found[t].clear();
    }
  }
  std::vector<int32_t> ids;
  std::vector<double> keys;
  ids.reserve(n), keys.reserve(n);
  for (int32_t u = 0; u < n; ++u)
    if (target_[u] >= 0) ids.push_back(u), keys.push_back(best_cost[u]);
  heap_.assign(ids, keys);
}

std::vector<uint8_t> lone_corners(const std::vector<int32_t>& triangles, size_t num_vertices) {
  std::vector<uint8_t> faces(num_vertices, 0), lone;
  for (int32_t v : triangles) faces[size_t(v)] = uint8_t(std::min(2, faces[size_t(v)] + 1));
  for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const int32_t* c = &triangles[t];
    if (faces[size_t(c[0])] != 1 || faces[size_t(c[1])] != 1 || faces[size_t(c[2])] != 1) continue;
    if (lone.empty()) lone.assign(num_vertices, 0);
    for (int j = 0; j < 3; ++j) lone[size_t(c[j])] = 1;
  }
  return lone;
}

bool Collapser::has_free_vertex() const {
  for (int32_t v = 0; v < int32_t(merged_into_.size()); ++v)
    if (merged_into_[v] < 0 && !s_.locked[v] && !lone(v)) return true;
  return false;
}

int32_t Collapser::survivor(int32_t v) {
  int32_t root = v;
  while (merged_into_[root] >= 0) root = merged_into_[root];
  while (merged_into_[v] >= 0) {
    const int32_t up = merged_into_[v];
    merged_into_[v] = root;
    v = up;
  }
  return root;
}

void Collapser::reweigh(std::vector<double> weight) {
  s_.weight = std::move(weight);
  for (CostCache& kept : kept_costs_) kept.clear();
  const int32_t n = vertices();
  std::vector<Best> best(n);
  parallel_for(0, n, kParallelMinCostly, [&](int32_t u) {
    if (merged_into_[u] < 0) best[u] = evaluate(u, false, scratch_.mine());
  });
  for (int32_t u = 0; u < n; ++u)
    if (merged_into_[u] < 0) settle(u, best[u]);
}

double Collapser::quadric_error() const {
  double sum = 0.0;
  for (int32_t v = 0; v < vertices(); ++v) {
    if (merged_into_[v] >= 0) continue;
    Quadric q;
    s_.quadrics.reduced(v, -1, q);
    sum += std::max(0.0, q.error(position(v)));
  }
  return sum;
}

void Collapser::neighbours(int32_t v, Scratch& scratch, std::vector<int32_t>& out) const {
  out.clear();
  const uint32_t stamp = ++scratch.stamp;
  for (const int32_t* t = faces_begin(v); t != faces_end(v); ++t)
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(*t) + j];
      if (w != v && scratch.mark[w] != stamp) {
        scratch.mark[w] = stamp;
        out.push_back(w);
      }
    }
}

int32_t Collapser::sector_at(int32_t t, int32_t v) const {
  for (int j = 0; j < 3; ++j)
    if ((*tri_)[3 * size_t(t) + j] == v) return s_.corner_sector[3 * size_t(t) + j];
  return -1;
}

void Collapser::remove_face(int32_t v, int32_t t) {
  // A flat star stays flat without t, unless t was the triangle the others were compared with.
  if (tracking_floors_ && (flat_star_[v].get() != 1 || flat_reference_[v].get() == t)) flat_star_[v].set(-1);
  int32_t* list = &pool_[begin_[v]];
  const int32_t size = size_[v];
  // t is in the list once. A wide vertex's list is usually still in the ascending order the
  // constructor wrote (only a collapse's survivor has faces appended): a bisection, as if it
  // were, finds t at once there, and the scan finds it in any order.
  int32_t i = size;
  if (size > kWideFan) {
    int32_t lo = 0, hi = size;
    while (lo < hi) {
      const int32_t mid = lo + (hi - lo) / 2;
      if (list[mid] < t) lo = mid + 1; else hi = mid;
    }
    if (lo < size && list[lo] == t) i = lo;
  }
  if (i == size) i = int32_t(std::find(list, list + size, t) - list);
  if (i == size) return;
  std::copy(list + i + 1, list + size, list + i);  // keep the order: it decides ties and summation order
  --size_[v];
}

void Collapser::append_faces(int32_t v, const int32_t* faces, int32_t count) {
  if (size_[v] + count > capacity_[v]) {
    // Out of room: the list moves to the end of the pool with space to grow.
    const int32_t capacity = 2 * (size_[v] + count);
    const int32_t start = static_cast<int32_t>(pool_.size());
    pool_.resize(pool_.size() + capacity);
    std::copy(pool_.begin() + begin_[v], pool_.begin() + begin_[v] + size_[v], pool_.begin() + start);
    begin_[v] = start;
    capacity_[v] = capacity;
  }
  std::copy(faces, faces + count, pool_.begin() + begin_[v] + size_[v]);
  size_[v] += count;
}

bool Collapser::placement(int32_t from, int32_t to, const Quadric& q, double x[3]) const {
  const double* pt = position(to);
  for (int i = 0; i < 3; ++i) x[i] = pt[i];
  if (!free_pair(from, to)) return false;
  // The same point either way round, so that the edge costs the same from both ends.
  if (from > to) std::swap(from, to), pt = position(to);
  const double* pf = position(from);
  double d[3], length2 = 0;
  for (int i = 0; i < 3; ++i) d[i] = pt[i] - pf[i], length2 += d[i] * d[i];
  if (q.minimum(x)) {
    // Trust the optimum only near the edge (a nearly flat or straight neighbourhood makes it
    // drift along the surface).
    double far2 = 0;
    for (int i = 0; i < 3; ++i) far2 += (x[i] - 0.5 * (pf[i] + pt[i])) * (x[i] - 0.5 * (pf[i] + pt[i]));
    if (far2 <= length2) return true;
  }
  // The best point on the edge: E(pf + t d) is quadratic in t.
  const double t = std::clamp(q.line_minimum(pf, d), 0.0, 1.0);
  for (int i = 0; i < 3; ++i) x[i] = pf[i] + t * d[i];
  return false;
}

double Collapser::cost(int32_t from, int32_t to) const {
  Quadric q;
  s_.quadrics.reduced(from, to, q);
  double x[3];
  placement(from, to, q, x);
  const double w = free_pair(from, to) ? std::max(s_.weight[from], s_.weight[to]) : s_.weight[from];
  double c = std::max(0.0, q.error(x));
  // A move along a curve: at least its span (a wide vertex's kept costs see only quadric changes).
  if (!span_.empty() && s_.curve_slot[from] >= 0 && kept_slot(from) < 0) {
    const int32_t k = s_.curve_slot[from], p = span_prev_[k], q = span_next_[k];
    const int onto = p < 0 || q < 0 ? -1 : s_.curve_order[q] == to ? 0 : s_.curve_order[p] == to ? 1 : -1;
    if (onto >= 0) c = std::max(c, span_[2 * size_t(k) + onto]);
  }
  return w * c;
}

// The links along each curve, every vertex live, and each curve vertex's span cost.
void Collapser::set_up_spans() {
  if (s_.curve_slot.empty()) return;
  const int32_t slots = int32_t(s_.curve_order.size());
  span_prev_.assign(slots, -1);
  span_next_.assign(slots, -1);
  span_.assign(2 * size_t(slots), 0.0);
  for (int32_t c = 0; c + 1 < int32_t(s_.curve_offsets.size()); ++c) {
    const int32_t begin = s_.curve_offsets[c], end = s_.curve_offsets[c + 1];
    const bool closed = s_.curve_closed[c];
    for (int32_t k = begin; k < end; ++k) {
      span_prev_[k] = k > begin ? k - 1 : closed ? end - 1 : -1;
      span_next_[k] = k + 1 < end ? k + 1 : closed ? begin : -1;
    }
  }
  for (int32_t k = 0; k < slots; ++k) refresh_span(k);
}

// Moving the curve vertex of slot k onto either live neighbour replaces its two edges with one
// joining them: span_weight times that edge's squared length times the squared distance of the
// farthest input curve point between them from it (0 past a gone end of an open curve). Onto the
// next (to[0]) the distances are measured from the previous, onto the previous (to[1]) from the
// next: the two agree only up to rounding.
void Collapser::span_of(int32_t k, double to[2]) const {
  to[0] = to[1] = 0.0;
  const int32_t p = span_prev_[k], q = span_next_[k];
  if (p < 0 || q < 0 || p == k) return;
  const int32_t c = s_.curve[s_.curve_order[k]];
  const int32_t begin = s_.curve_offsets[c], end = s_.curve_offsets[c + 1];
  const double* a[2] = {position(s_.curve_order[p]), position(s_.curve_order[q])};
  double ab[2][3], length2 = 0;
  for (int i = 0; i < 3; ++i) ab[0][i] = a[1][i] - a[0][i], ab[1][i] = -ab[0][i], length2 += ab[0][i] * ab[0][i];
  double far2[2] = {0, 0};
  for (int32_t i = p + 1 < end ? p + 1 : begin; i != q; i = i + 1 < end ? i + 1 : begin) {
    const double* x = &s_.curve_points[3 * size_t(i)];
    for (int e = 0; e < 2; ++e) {
      double ax[3], t = 0;
      for (int j = 0; j < 3; ++j) ax[j] = x[j] - a[e][j], t += ax[j] * ab[e][j];
      t = length2 > 0 ? std::clamp(t / length2, 0.0, 1.0) : 0.0;
      double d2 = 0;
      for (int j = 0; j < 3; ++j) d2 += (ax[j] - t * ab[e][j]) * (ax[j] - t * ab[e][j]);
      far2[e] = std::max(far2[e], d2);
    }
  }
  for (int e = 0; e < 2; ++e) to[e] = s_.span_weight * length2 * far2[e];
}

// Slot k's span cost anew, if a curve vertex holds it (not a corner).
void Collapser::refresh_span(int32_t k) {
  if (k < 0 || s_.curve_slot[s_.curve_order[k]] != k) return;
  span_of(k, &span_[2 * size_t(k)]);
}

// u is gone: its neighbours along the curve are linked, and their spans grow. A dead end (an open
// curve's end vertex, which holds no slot) leaves its neighbour the curve's end.
void Collapser::unlink_span(int32_t u) {
  if (span_.empty() || s_.curve[u] < 0) return;
  const int32_t k = s_.curve_slot[u];
  if (k < 0) {
    const int32_t c = s_.curve[u], begin = s_.curve_offsets[c], end = s_.curve_offsets[c + 1];
    if (s_.curve_order[begin] == u && span_next_[begin] >= 0)
      span_prev_[span_next_[begin]] = -1, refresh_span(span_next_[begin]);
    if (s_.curve_order[end - 1] == u && span_prev_[end - 1] >= 0)
      span_next_[span_prev_[end - 1]] = -1, refresh_span(span_prev_[end - 1]);
    return;
  }
  const int32_t p = span_prev_[k], q = span_next_[k];
  if (p >= 0) span_next_[p] = q;
  if (q >= 0) span_prev_[q] = p;
  span_prev_[k] = span_next_[k] = -1;
  refresh_span(p);
  refresh_span(q);
}

// v moved: the spans that end at it change.
void Collapser::span_moved(int32_t v) {
  if (span_.empty() || s_.curve_slot[v] < 0) return;
  const int32_t k = s_.curve_slot[v];
  refresh_span(span_prev_[k]);
  refresh_span(span_next_[k]);
}

void Collapser::queue(int32_t u, int32_t v, double c) {
  target_[u] = v;
  dirty_[u] = 0;
  heap_.set(u, c);
}

// Calls fn(v, cost of u's collapse onto v) for each v of `around`, with the costs kept where u is
// wide (CostCache). For one u at a time on any thread (a batch's evaluations are of distinct
// vertices).
template <class Fn>
void Collapser::for_each_cost(int32_t u, const std::vector<int32_t>& around, const Fn& fn) const {
  const int32_t slot = kept_slot(u);
  if (slot < 0) {
    for (int32_t v : around) fn(v, cost(u, v));
    return;
  }
  CostCache& kept = kept_costs_[slot];
  const uint32_t since_u = changed_at_[u];
  auto alive = [&](int32_t v) { return merged_into_[v] < 0; };
  for (int32_t v : around) {
    const CostCache::Entry* e = kept.find(v);
    if (e && e->time >= since_u && e->time >= changed_at_[v]) {
      fn(v, e->cost);
    } else {
      const double c = cost(u, v);
      kept.put(v, clock_, c, alive);
      fn(v, c);
    }
  }
}

// u's cheapest collapse (lowest id on ties), or none (target -1) for a locked vertex or one at
// its quota. Checks wait until it is popped (most queued collapses are superseded before that);
// with `checked`, the cheapest one that passes them. Reads the state only: safe in parallel.
Collapser::Best Collapser::evaluate(int32_t u, bool checked, Scratch& scratch) const {
  Best best;
  if (s_.locked[u] || lone(u) || at_quota(u) || (!held_.empty() && held_[u])) return best;
  neighbours(u, scratch, scratch.list);
  if (!checked) {
    for_each_cost(u, scratch.list, [&](int32_t v, double c) {
      if (best.target < 0 || c < best.cost || (c == best.cost && v < best.target)) best = {v, c};
    });
    return best;
  }
  scratch.costs.clear();
  for_each_cost(u, scratch.list, [&](int32_t v, double c) { scratch.costs.push_back({c, v}); });
  // A wide vertex tries its kWideTries cheapest: each check of a collapse there reads its faces,
  // and the centre of a fan of thousands, re-evaluated after every collapse on its rim, read them
  // for every neighbour (a cylinder of 5,000 segments with fanned caps: 0.8 -> 12.6 s). Only
  // those are put in order (the pairs are distinct: the same first ones as a whole sort).
  const size_t tries = size_[u] > kWideFan ? std::min<size_t>(kWideTries, scratch.costs.size()) : scratch.costs.size();
  std::partial_sort(scratch.costs.begin(), scratch.costs.begin() + tries, scratch.costs.end());
  for (size_t i = 0; i < tries; ++i)
    if (allowed(u, scratch.costs[i].second, scratch)) return {scratch.costs[i].second, scratch.costs[i].first};
  return best;
}

int64_t Collapser::check_kept_state() const {
  if (!tracking_floors_) return 0;
  int64_t checked = 0;
  Scratch scratch;
  scratch.mark.assign(merged_into_.size(), 0);
  for (int32_t v = 0; v < vertices(); ++v) {
    if (merged_into_[v] >= 0) continue;
    if (const int8_t known = flat_star_[v].get(); known >= 0) {
      int32_t first = -1;
      const bool flat = walk_flat_star(v, &first);
      if (flat != bool(known) || (flat && first != flat_reference_[v].get())) return -1;
      ++checked;
    }
    if (kept_costs_of_[v] < 0) continue;
    neighbours(v, scratch, scratch.list);
    bool same = true;
    for_each_cost(v, scratch.list, [&](int32_t u, double c) { same = same && c == cost(v, u); });
    if (!same) return -1;
    checked += int64_t(scratch.list.size());
  }
  return checked;
}

// Stamps v's quadric or position as changed: the costs kept with it (for_each_cost) are stale.
void Collapser::changed(int32_t v) {
  if (changed_at_.empty()) return;
  if (++clock_ == 0) {  // the clock wrapped: start again with nothing kept
    std::fill(changed_at_.begin(), changed_at_.end(), 0);
    for (CostCache& kept : kept_costs_) kept.clear();
  }
  changed_at_[v] = clock_;
}

// Queues u's cheapest collapse, or takes u out of the queue when it has none: it waits until a
// collapse next to it looks again.
void Collapser::update(int32_t u, bool checked) { settle(u, evaluate(u, checked, scratch_[0])); }

void Collapser::settle(int32_t u, Best best) {
  if (best.target >= 0) {
    queue(u, best.target, best.cost);
  } else {
    target_[u] = -1;
    dirty_[u] = 0;
    heap_.remove(u);
  }
}

bool Collapser::zero_area(int32_t t) const {
  // In the caller's coordinates: that is what the output holds.
  const int32_t* c = &(*tri_)[3 * size_t(t)];
  const double* a = world(c[0]);
  const double* b = world(c[1]);
  const double* d = world(c[2]);
  double u[3], w[3];
  for (int i = 0; i < 3; ++i) u[i] = b[i] - a[i], w[i] = d[i] - a[i];
  return u[1] * w[2] - u[2] * w[1] == 0.0 && u[2] * w[0] - u[0] * w[2] == 0.0 && u[0] * w[1] - u[1] * w[0] == 0.0;
}

bool Collapser::thin(int32_t t, double min_shape) const {
  if (min_shape <= 0.0) return false;
  double n[3];
  const int32_t* c = &(*tri_)[3 * size_t(t)];
  return shape(c, c[0], position(c[0]), std::sqrt(face_normal2(t, n))) < min_shape;
}

std::vector<int32_t> Collapser::zero_area_face_list() const {
  std::vector<int32_t> list;
  for (int32_t t = 0; t < int32_t(alive_face_.size()); ++t)
    if (alive_face_[t] && zero_area(t)) list.push_back(t);
  return list;
}

bool Collapser::place(int32_t v, const double* world, int32_t face) {
  double at[3];
  for (int i = 0; i < 3; ++i) at[i] = (world[i] - s_.center[i]) * (1.0 / s_.extent);
  ShapeFloor floor{v, -1};
  if (!keeps_shape(v, -1, at, floor)) return false;
  double* p = &s_.positions[3 * size_t(v)];
  double* w = &s_.world[3 * size_t(v)];
  double keep_p[3], keep_w[3];
  for (int i = 0; i < 3; ++i) keep_p[i] = p[i], keep_w[i] = w[i], p[i] = at[i], w[i] = world[i];
  if (!zero_area(face)) return changed(v), moved_floor_bounds(v), span_moved(v), true;
  for (int i = 0; i < 3; ++i) p[i] = keep_p[i], w[i] = keep_w[i];  // no gain: back
  return false;
}

int32_t Collapser::zero_area_faces() const {
  int32_t count = 0;
  for (size_t t = 0; t < alive_face_.size(); ++t) count += alive_face_[t] && zero_area(int32_t(t));
  return count;
}

int32_t Collapser::remove_thin(double min_shape, Stop keep, ThinRules rules) {
  // Candidates are found up front: a collapse makes no zero-area triangle, and a thin one only
  // beside one as thin or thinner (keeps_shape); a failed candidate may pass after its
  // neighbours collapsed, hence the rounds.
  const int32_t m = static_cast<int32_t>(alive_face_.size());
  std::vector<uint8_t> flagged(m, 0);
  parallel_for(0, m, 100000, [&](int32_t t) { flagged[t] = alive_face_[t] && (zero_area(t) || thin(t, min_shape)); });
  std::vector<int32_t> candidates;
  for (int32_t t = 0; t < m; ++t)
    if (flagged[t]) candidates.push_back(t);
  // On a fan of slivers (a corner of more than kWideFan faces) a triangle beside a collapse's
  // survivor waits for the next round: each collapse there leaves the next sliver as thin, and
  // collapsing that one into the same survivor swept a whole arc into one triangle (a fanned
  // disc's rim: a wedge of 1.8 radians at 10 %). Once a round per vertex, the collapses spread
  // evenly, and never into the fan's centre instead.
  // (The rounds' marks are made when the first fan is met: most meshes have none.)
  std::vector<int32_t> took;
  auto waits = [&](int32_t x, int32_t round) { return !took.empty() && took[x] == round; };
  auto in_fan = [&](const int32_t* c) {
    return min_shape > 0.0 && (size_[c[0]] > kWideFan || size_[c[1]] > kWideFan || size_[c[2]] > kWideFan);
  };
  int32_t collapses = 0;
  for (int32_t round = 0, progress = !candidates.empty(); progress; ++round) {
    progress = false;
    for (int32_t t : candidates) {
      if (reached(keep)) return collapses;
      if (!alive_face_[t] || !(zero_area(t) || thin(t, min_shape))) continue;
      const int32_t* c = &(*tri_)[3 * size_t(t)];
      const bool fan = in_fan(c);
      if (rules.fans_only && !fan && !zero_area(t)) continue;
      if (fan && took.empty()) took.assign(merged_into_.size(), -1);
      if (fan && (waits(c[0], round) || waits(c[1], round) || waits(c[2], round))) continue;
      // The six directed collapses, those moving a free vertex first: taken in corner order, a
      // sliver at a rim's bend moved the bend's vertex along the sliver's long edge (a box-cut
      // gyroid's rim lost a corner of 0.29 % of the diagonal at 50 %). The border moves after
      // them in corner order, or cheapest first (rules).
      int order[6] = {0, 1, 2, 3, 4, 5};
      auto from = [&](int j) { return c[j % 3]; };
      auto to = [&](int j) { return c[(j % 3 + (j < 3 ? 1 : 2)) % 3]; };
      int* border = std::stable_partition(order, order + 6, [&](int j) { return s_.curve[from(j)] < 0; });
      if (rules.border_moves_by_cost) {
        double cost_of[6];
        for (int* j = border; j != order + 6; ++j) cost_of[*j] = cost(from(*j), to(*j));
        std::stable_sort(border, order + 6, [&](int a, int b) { return cost_of[a] < cost_of[b]; });
      }
      for (int j : order) {
        const int32_t u = from(j), v = to(j);
        if (s_.locked[u] || !allowed(u, v, scratch_[0])) continue;
        collapse(u, v);
        refresh(u, v);
        if (fan) took[v] = round;
        ++collapses;
        progress = true;
        break;
      }
    }
  }
  return collapses;
}

// A batch's checks and costs run on the team only when they are a few hundred microseconds of
// work: below that, waking the workers costs about what they save (they sleep between batches).
constexpr int32_t kParallelChecks = 64;      // reserved collapses to check
constexpr int32_t kParallelCostWork = 512;  // neighbour pairs to cost + 8 per evaluation

// Collapses per batch: 1 (exactly greedy) near the end and on small meshes, up to 128 when
// many remain, so that the checks and costs of a batch can run in parallel.
int32_t Collapser::batch_size(int32_t excess) const {
  return std::clamp(std::min(excess / 64, alive_vertices_ / 1024), 1, kMaxBatch);
}

void Collapser::use_arrays(std::vector<int32_t>& triangles, std::vector<int32_t>& corner_source) {
  tri_ = &triangles;
  corner_source_ = &corner_source;
}

void Collapser::set_quota(std::vector<int32_t> quota) { s_.quota = std::move(quota); }

void Collapser::fit_threads() {
  const int32_t n = static_cast<int32_t>(s_.weight.size());
  scratch_ = PerThread<Scratch>(max_threads());
  for (int t = 0; t < scratch_.size(); ++t) scratch_[t].mark.assign(n, 0);
}

int32_t Collapser::run(Stop target, const BeforeTail& before_tail) {
  int32_t collapses = 0;
  Batch batch;
  bool in_tail = false;
  int32_t last_size = 0;  // of the last batch: one collapse, so none was left out at the target
  while (!reached(target)) {
    check_cancelled("collapses");
    if (heap_.empty()) {
      // Some region could not reach its quota: the others give the rest, by cost alone. Then,
      // where every collapse left fails a check, those whose point only fails the shape rule
      // may keep the survivor where it is (rescue_).
      if (!use_quota_ && rescue_) break;
      if (use_quota_)
        use_quota_ = false;
      else
        rescue_ = true;
      for (int32_t u = 0; u < int32_t(merged_into_.size()); ++u)
        if (merged_into_[u] < 0) update(u);
      continue;
    }
    const int32_t size = batch_size(target.faces > 0 ? (alive_faces_ - target.faces) / 2 : alive_vertices_ - target.vertices);
    if (before_tail && !in_tail && target.faces == 0 && use_quota_ && size != batch_size(INT32_MAX)) before_tail(*this, collapses);
    in_tail = in_tail || size != batch_size(INT32_MAX);
    last_size = size;
    take_batch(batch, std::min(size, batch_cap_));
    const uint32_t ring = ++ring_stamp_;
    reserve_batch(batch, ring);
    check_reserved(batch);
    collapses += apply_batch(batch, target);
    batch_cap_ = next_batch_cap(batch, batch_cap_);
    cost_after_batch(batch, ring);
    settle_survivors(batch, ring);
  }
  // Batches of one collapse all the way (fewer than 2048 vertices left): the target never
  // mattered, and a lower one passes through this state.
  if (before_tail && !in_tail && last_size == 1 && target.faces == 0 && use_quota_ && reached(target))
    before_tail(*this, collapses);
  return collapses;
}

// The cheapest queued collapses, in cost order (at most `size`).
void Collapser::take_batch(Batch& batch, int32_t size) {
  batch.vertices.clear();
  batch.key.clear();
  while (int32_t(batch.vertices.size()) < size && !heap_.empty()) {
    const int32_t u = heap_.top();
    const double key = heap_.top_key();
    heap_.remove(u);
    if (at_quota(u)) {
      target_[u] = -1;
      continue;
    }
    batch.vertices.push_back(u);
    batch.key.push_back(key);
  }
  taken_ += int64_t(batch.vertices.size());
}

// The next batch's largest size. Where the cheapest collapses all touch one another (equal costs
// on a flat region, whose ties go by vertex id, so neighbours come out together), a full batch
// reserves one and queues the rest again: a hundred heap operations for each collapse. The cap
// then drops to twice the collapses that did not wait, and doubles back batch by batch.
int32_t Collapser::next_batch_cap(const Batch& batch, int32_t cap) {
  const int32_t taken = int32_t(batch.vertices.size());
  const int32_t waited = int32_t(std::count(batch.status.begin(), batch.status.end(), uint8_t(kWait)));
  if (taken >= 16 && 8 * waited > 7 * taken) return std::max(2, 2 * (taken - waited));
  return std::min(2 * cap, kMaxBatch);
}

// A collapse with a wide fan's centre at one end is checked (as check_reserved would) before its
// ring, the whole fan, is marked: such collapses are nearly always refused (the fan would fold),
// and each marking walked the fan twice. kReady if it may go on.
uint8_t Collapser::refused_at_fan(int32_t u, int32_t v, double key) {
  if (!at_fan(u, v)) return kReady;
  if (key != cost(u, v)) return kEvaluate;
  return allowed(u, v, scratch_[0]) ? kReady : kEvaluateChecked;
}

// Reserve, in cost order, the neighbourhoods of collapses no earlier one of the batch touches:
// applied in any order they see the state at the start of the batch, so their checks and costs
// can be computed at once (in parallel). The others wait in the queue.
void Collapser::reserve_batch(Batch& batch, uint32_t ring) {
  const int32_t count = int32_t(batch.vertices.size());
  batch.status.assign(count, kReady);
  batch.reserved.clear();
  for (int32_t i = 0; i < count; ++i) {
    const int32_t u = batch.vertices[i], v = target_[u];
    if (dirty_[u] || merged_into_[v] >= 0) {
      batch.status[i] = kEvaluate;  // its key was a lower bound, or its collapse went stale
    } else if (const uint8_t refused = refused_at_fan(u, v, batch.key[i]); refused != kReady) {
      batch.status[i] = refused;
    } else if (mark_ring(u, v, ring)) {
      batch.reserved.push_back(i);
    } else {
      batch.status[i] = kWait;
      queue(u, v, batch.key[i]);
    }
  }
}

// The reserved collapses whose cost changed or which are no longer allowed are evaluated anew.
void Collapser::check_reserved(Batch& batch) {
  const int32_t checks = int32_t(batch.reserved.size());
  parallel_for_dynamic(0, checks, 4, kParallelChecks, [&](int32_t k) {
    const int32_t i = batch.reserved[k], u = batch.vertices[i], v = target_[u];
    if (at_fan(u, v)) return;  // refused_at_fan checked it on the same state
    if (batch.key[i] != cost(u, v)) {
      batch.status[i] = kEvaluate;
    } else if (!allowed(u, v, scratch_.mine())) {
      batch.status[i] = kEvaluateChecked;
    }
  });
}

// Applies the ready collapses in cost order (until the target), notes those to evaluate anew
// and the survivors; returns how many collapsed.
int32_t Collapser::apply_batch(Batch& batch, Stop target) {
  int32_t collapses = 0;
  batch.pending.clear();
  batch.pending_checked.clear();
  batch.survivors.clear();
  for (int32_t i = 0; i < int32_t(batch.vertices.size()); ++i) {
    const int32_t u = batch.vertices[i], v = target_[u];
    if (batch.status[i] == kWait) continue;
    if (batch.status[i] != kReady) {
      batch.pending.push_back(u);
      batch.pending_checked.push_back(batch.status[i] == kEvaluateChecked);
      continue;
    }
    if (reached(target)) {
      queue(u, v, batch.key[i]);
      continue;
    }
    if (at_quota(u)) {
      target_[u] = -1;
      continue;
    }
    collapse(u, v);
    batch.survivors.push_back(v);
    ++collapses;
  }
  return collapses;
}

// Costs after the batch (in parallel): every collapse of each survivor v and, from each
// neighbour x, the collapse onto v (the same number when both are free); popped vertices that
// need a new evaluation are evaluated and settled.
void Collapser::cost_after_batch(Batch& batch, uint32_t ring) {
  batch.pair_from.clear();
  batch.pair_to.clear();
  for (int32_t v : batch.survivors) {
    neighbours(v, scratch_[0], scratch_[0].list);
    for (int32_t x : scratch_[0].list) batch.pair_from.push_back(v), batch.pair_to.push_back(x);
  }
  const int32_t pairs = int32_t(batch.pair_from.size()), evaluations = int32_t(batch.pending.size());
  batch.pair_cost_from.assign(pairs, 0.0);
  batch.pair_cost_to.assign(pairs, 0.0);
  batch.pending_best.assign(evaluations, Best());
  std::atomic<int64_t> next_evaluation{0};
  parallel_region(pairs + 8 * evaluations >= kParallelCostWork ? max_threads() : 1, [&](Team& team) {
    team.for_static(0, pairs, [&](int32_t i) {
      const int32_t v = batch.pair_from[i], x = batch.pair_to[i];
      const bool v_queues = queues(v), x_queues = queues(x);
      if (v_queues) batch.pair_cost_from[i] = cost(v, x);
      if (x_queues) batch.pair_cost_to[i] = v_queues && free_pair(x, v) ? batch.pair_cost_from[i] : cost(x, v);
    });
    team.for_dynamic(next_evaluation, evaluations, 4, [&](int32_t i) {
      batch.pending_best[i] = evaluate(batch.pending[i], batch.pending_checked[i], scratch_.mine());
    });
  });
  for (int32_t i = 0; i < evaluations; ++i) {
    settle(batch.pending[i], batch.pending_best[i]);
    settled_[batch.pending[i]] = ring;  // settled: the neighbour updates below leave it alone
  }
}

// Each survivor takes its cheapest collapse; its neighbours not settled in this batch are
// offered the collapse onto it.
void Collapser::settle_survivors(const Batch& batch, uint32_t ring) {
  const int32_t pairs = int32_t(batch.pair_from.size());
  for (int32_t i = 1, start = 0; i <= pairs; ++i) {
    if (i < pairs && batch.pair_from[i] == batch.pair_from[start]) continue;
    // pairs [start, i) belong to one survivor
    const int32_t v = batch.pair_from[start];
    Best best;
    if (queues(v))
      for (int32_t k = start; k < i; ++k)
        if (best.target < 0 || batch.pair_cost_from[k] < best.cost ||
            (batch.pair_cost_from[k] == best.cost && batch.pair_to[k] < best.target))
          best = {batch.pair_to[k], batch.pair_cost_from[k]};
    settle(v, best);
    for (int32_t k = start; k < i; ++k) {
      const int32_t x = batch.pair_to[k];
      if (settled_[x] == ring) continue;
      // A wide neighbour whose checks all failed looks again with its checks, once a batch: were it
      // queued unchecked, a flat fan's centre (cost 0) topped the queue again after every batch
      // and, reserving its whole rim, emptied the next one.
      if (target_[x] < 0 && size_[x] > kWideFan && queues(x)) {
        update(x, true);
        settled_[x] = ring;
        continue;
      }
      offer(x, v, merged_from_[v], batch.pair_cost_to[k]);
    }
    start = i;
  }
}

// Marks u, v and their neighbours for this batch; false (nothing marked) if any already is. A
// wide vertex beside the edge (a fan's centre) may be beside several collapses of a batch: their
// checks and costs read its position, which none of them moves, and none of its own state (its
// rim's collapses had gone one per batch: a fanned cap of 69,444 took 70,000 batches).
bool Collapser::mark_ring(int32_t u, int32_t v, uint32_t ring) {
  auto beside = [&](int32_t w) {
    const int32_t slot = kept_slot(w);
    return slot >= 0 && size_[w] > kWideFan && w != u && w != v ? slot : -1;
  };
  for (int32_t w : {u, v})
    if (const int32_t slot = kept_slot(w); waiting_[w] == ring || (slot >= 0 && beside_[slot] == ring)) return false;
  for (int32_t w : {u, v}) {
    ring_faces_ += faces_end(w) - faces_begin(w);
    for (const int32_t* t = faces_begin(w); t != faces_end(w); ++t)
      for (int j = 0; j < 3; ++j)
        if (waiting_[(*tri_)[3 * size_t(*t) + j]] == ring) return false;
  }
  for (int32_t w : {u, v})
    for (const int32_t* t = faces_begin(w); t != faces_end(w); ++t)
      for (int j = 0; j < 3; ++j) {
        const int32_t x = (*tri_)[3 * size_t(*t) + j];
        if (const int32_t slot = beside(x); slot >= 0)
          beside_[slot] = ring;
        else
          waiting_[x] = ring;
      }
  return true;
}

// x's collapse onto the survivor v of a collapse of `removed` now costs c. A neighbour queued
// for the removed vertex or for v keeps its old cost as a lower bound (dirty) unless the new
// collapse onto v is at least as cheap; others take v if it is now cheaper. A neighbour without
// a queued collapse (its checks failed) looks again.
void Collapser::offer(int32_t x, int32_t v, int32_t removed, double c) {
  if (!queues(x)) return;
  if (target_[x] < 0) {
    update(x);
    return;
  }
  const double key = heap_.key_of(x);
  if (dirty_[x] || target_[x] == removed || target_[x] == v) {
    if (c <= key) {
      queue(x, v, c);
    } else {
      dirty_[x] = 1;
    }
  } else if (c < key) {
    queue(x, v, c);
  }
}

// Link condition (Dey et al. 1999): u and v share exactly the vertices opposite their edge, and v
// keeps at least three neighbours (two on a boundary edge at the end); then the surface stays a
// manifold of the same topology. An interior u may go to any neighbour; a u on a border curve only
// along the curve, so every border keeps its course and its sides: each of u's sectors (one for a
// boundary, two for a crease, k for a non-manifold edge of k sheets) is a fan from the curve's
// other edge to this one and holds exactly one of the edge's triangles.
bool Collapser::allowed(int32_t u, int32_t v, Scratch& scratch) const {
  if (size_[u] > kWideFan || size_[v] > kWideFan) return allowed_wide(u, v, scratch);
  std::vector<uint32_t>& mark = scratch.mark;
  const uint32_t su = ++scratch.stamp;
  int32_t nu = 0, faces_u = 0;
  bool found = false;
  int32_t on_edge[kMaxSheets], count = 0;
  for (const int32_t* t = faces_begin(u); t != faces_end(u); ++t) {
    ++faces_u;
    bool with_v = false;
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(*t) + j];
      if (w == u) continue;
      with_v |= w == v;
      if (mark[w] != su) {
        mark[w] = su;
        ++nu;
      }
    }
    if (with_v) {
      if (count == kMaxSheets) return false;
      on_edge[count++] = *t;
      found = true;
    }
  }
  if (!found) return false;
  const int32_t cu = s_.curve[u];
  if (cu < 0) {
    if (nu != faces_u || count != 2) return false;  // a closed fan around u
  } else {
    if (!along_curve(u, v) || !curve_fans(u, nu, faces_u, on_edge, count)) return false;
  }
  const uint32_t sv = ++scratch.stamp;
  int32_t nv = 0, shared = 0;
  for (const int32_t* t = faces_begin(v); t != faces_end(v); ++t)
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(*t) + j];
      if (w == v || mark[w] == sv) continue;
      shared += mark[w] == su;
      mark[w] = sv;
      ++nv;
    }
  if (shared != count || duplicates_a_face(u, v, on_edge, count)) return false;
  if (cu >= 0 && merges_unlike_edges(u, v, on_edge, count)) return false;
  // v keeps three neighbours, or two along a boundary (count 1) once nothing else collapses
  // (rescue_): a disc's last quad becomes its one triangle, v a corner of it (Dey et al.'s
  // condition with the boundary's dummy vertex); earlier it would cost the small discs' shape.
  if (nu + nv < shared + (count == 1 && rescue_ ? 4 : 5)) return false;
  double x[3];
  return shaped_placement(u, v, x) >= 0 && (!fan_check_ || keeps_fan(u, v, x, scratch));
}

// set_fan_check's check of the triangles around u and v that the collapse keeps, u and v at x.
bool Collapser::keeps_fan(int32_t u, int32_t v, const double* x, Scratch& scratch) const {
  std::vector<double>& fan = scratch.fan;
  fan.clear();
  auto gather = [&](int32_t end, int32_t other) {
    for (const int32_t* t = faces_begin(end); t != faces_end(end); ++t) {
      if (has(*t, other)) continue;  // the collapse removes it
      for (int j = 0; j < 3; ++j) {
        const int32_t w = (*tri_)[3 * size_t(*t) + j];
        const double* at = w == end ? x : position(w);
        fan.insert(fan.end(), at, at + 3);
      }
    }
  };
  gather(u, v);
  gather(v, u);
  return fan_check_(fan.data(), int32_t(fan.size() / 9));
}

// allowed() where an end has more than kWideFan faces (the apex of a cone, the centre of a
// fanned disc): the same conditions, but what walks a wide end's faces comes last, after the
// cheap ones, and the link is read from the narrow end's neighbours, so that most refusals cost
// a few faces instead of the valence.
bool Collapser::allowed_wide(int32_t u, int32_t v, Scratch& scratch) const {
  const int32_t narrow = size_[u] <= size_[v] ? u : v, wide = narrow == u ? v : u;
  int32_t on_edge[kMaxSheets], count = 0;
  for (const int32_t* t = faces_begin(narrow); t != faces_end(narrow); ++t)
    if (has(*t, wide)) {
      if (count == kMaxSheets) return false;
      on_edge[count++] = *t;
    }
  if (count == 0) return false;
  const int32_t cu = s_.curve[u];
  if (cu < 0 && count != 2) return false;
  if (cu >= 0 && !along_curve(u, v)) return false;
  const int32_t shared = common_neighbours(narrow, wide, scratch);
  if (shared != count || duplicates_a_face(u, v, on_edge, count)) return false;
  if (cu >= 0 && merges_unlike_edges(u, v, on_edge, count)) return false;
  double x[3];
  if (shaped_placement(u, v, x) < 0) return false;
  if (fan_check_ && !keeps_fan(u, v, x, scratch)) return false;
  const int32_t nu = count_neighbours(u, INT32_MAX, scratch), faces_u = size_[u];
  if (cu < 0 ? nu != faces_u : !curve_fans(u, nu, faces_u, on_edge, count)) return false;
  const int32_t need = shared + (count == 1 && rescue_ ? 4 : 5) - nu;
  return need <= 0 || count_neighbours(v, need, scratch) >= need;
}

// How many neighbours a (a itself not counted) and b have in common, from a's faces.
int32_t Collapser::common_neighbours(int32_t a, int32_t b, Scratch& scratch) const {
  const uint32_t stamp = ++scratch.stamp;
  int32_t shared = 0;
  for (const int32_t* t = faces_begin(a); t != faces_end(a); ++t)
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(*t) + j];
      if (w == a || w == b || scratch.mark[w] == stamp) continue;
      scratch.mark[w] = stamp;
      shared += faces_holding(w, b, 1) > 0;
    }
  return shared;
}

// v's distinct neighbours, counted up to `enough`.
int32_t Collapser::count_neighbours(int32_t v, int32_t enough, Scratch& scratch) const {
  const uint32_t stamp = ++scratch.stamp;
  int32_t found = 0;
  for (const int32_t* t = faces_begin(v); t != faces_end(v) && found < enough; ++t)
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(*t) + j];
      if (w != v && scratch.mark[w] != stamp) scratch.mark[w] = stamp, ++found;
    }
  return found;
}

// The triangles holding both a and b, counted up to `enough`, from the shorter face list.
int32_t Collapser::faces_holding(int32_t a, int32_t b, int32_t enough) const {
  if (size_[a] > size_[b]) std::swap(a, b);
  int32_t found = 0;
  for (const int32_t* t = faces_begin(a); t != faces_end(a) && found < enough; ++t) found += has(*t, b);
  return found;
}

// Where collapsing u into v puts v: 1 at the quadric optimum, 0 elsewhere on the edge, -1
// nowhere (a triangle around the point would be too thin: the shape rule). In a rescue (run)
// a free pair whose point fails the rule may keep v where it is instead (0).
int Collapser::shaped_placement(int32_t u, int32_t v, double x[3]) const {
  Quadric q;
  s_.quadrics.reduced(u, v, q);
  const bool optimum = placement(u, v, q, x);
  ShapeFloor floor{u, v};
  if (keeps_shape(u, v, x, floor) && keeps_shape(v, u, x, floor)) return optimum ? 1 : 0;
  if (!rescue_ || !free_pair(u, v)) return -1;
  for (int i = 0; i < 3; ++i) x[i] = position(v)[i];
  return keeps_shape(u, v, x, floor) && keeps_shape(v, u, x, floor) ? 0 : -1;
}

// Are u's triangles around the edge laid out as on a curve? A curve vertex's sectors each hold
// one of them (count fans from the curve's other edge to this one, sharing only those two
// neighbours: faces_u - count + 2 of them); a dead end's each hold two (count / 2 fans from the
// edge round to it again, sharing only v: faces_u - count / 2 + 1), and only along its
// non-manifold edge.
bool Collapser::curve_fans(int32_t u, int32_t nu, int32_t faces_u, const int32_t* on_edge, int32_t count) const {
  const int32_t per_sector = is_dead_end(u) ? 2 : 1;
  if (per_sector == 2 && (count < 3 || count % 2 != 0)) return false;
  if (nu != faces_u - count / per_sector + 3 - per_sector) return false;
  for (int32_t i = 0; i < count; ++i) {
    int32_t same = 0;
    for (int32_t j = 0; j < count; ++j) same += sector_at(on_edge[i], u) == sector_at(on_edge[j], u);
    if (same != per_sector) return false;
  }
  return true;
}

// May curve vertex u go to v? Only along its curve (or onto a locked vertex), and only while the
// curve keeps its shape: a closed one more than three vertices, an open one an edge.
bool Collapser::along_curve(int32_t u, int32_t v) const {
  const int32_t cu = s_.curve[u];
  if (s_.curve[v] != cu && !s_.locked[v]) return false;
  return s_.curve_closed[cu] ? s_.curve_size[cu] > 3 : curve_keeps_an_edge(cu);
}

// An open curve keeps at least one edge (two vertices, its locked ends included): shrunk to a
// point, sheets that touched along it would touch at a vertex only.
bool Collapser::curve_keeps_an_edge(int32_t curve) const {
  const int32_t locked_ends = s_.curve_locked_ends.empty() ? 2 : s_.curve_locked_ends[curve];
  return s_.curve_size[curve] - 1 + locked_ends >= 2;
}

// Would collapsing u into v turn a triangle (u, a, b) into one v already has? Only possible when
// a and b are both opposite the edge, which the link condition allows; around a non-manifold
// vertex (a sealed wing on a non-manifold edge) that would delete the wing. Each triangle is
// looked for in the shortest face list of its corners, so a wide u, v or opposite is not walked.
bool Collapser::duplicates_a_face(int32_t u, int32_t v, const int32_t* on_edge, int32_t count) const {
  if (count < 2) return false;
  int32_t opposite[kMaxSheets];
  for (int32_t i = 0; i < count; ++i)
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(on_edge[i]) + j];
      if (w != u && w != v) opposite[i] = w;
    }
  auto holds = [&](int32_t a, int32_t b, int32_t c) {  // a triangle (a, b, c), from the shortest list
    int32_t shortest = size_[a] <= size_[b] ? a : b;
    if (size_[c] < size_[shortest]) shortest = c;
    for (const int32_t* t = faces_begin(shortest); t != faces_end(shortest); ++t)
      if (has(*t, a) && has(*t, b) && has(*t, c)) return true;
    return false;
  };
  for (int32_t i = 0; i < count; ++i)
    for (int32_t k = i + 1; k < count; ++k)
      if (opposite[i] != opposite[k] && holds(opposite[i], opposite[k], u) && holds(opposite[i], opposite[k], v))
        return true;
  return false;
}

// Collapsing u into v merges each edge (u, o) with (v, o), o opposite the edge: the merged edge
// has the triangles of both but the vanished one on each. Unless one of them is an ordinary
// two-triangle edge, that count is neither's: a sheet of a non-manifold curve that is a single
// triangle, or a hole bounded by it, would vanish. (Interior u: all its edges are ordinary.)
bool Collapser::merges_unlike_edges(int32_t u, int32_t v, const int32_t* on_edge, int32_t count) const {
  for (int32_t i = 0; i < count; ++i) {
    int32_t o = -1;
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(on_edge[i]) + j];
      if (w != u && w != v) o = w;
    }
    if (faces_holding(u, o, 3) == 2) continue;
    if (faces_holding(v, o, 3) != 2) return true;
  }
  return false;
}

// The squared shape quality of the thinnest triangle with area around `v`, capped at the limit's
// (kMinShape unless set_shape_limits changed it): a move or collapse at v may leave a triangle that
// thin, so that it never makes the worst triangle around it worse, and a needle (the ends of an
// input edge far shorter than its neighbours, kept by the first pass) can collapse even when a
// neighbour then ends a little below kMinShape. Before this floor, a triangle could not end below
// kMinShape unless it already was, and then with no limit: such needles stayed and stretched as
// their far corner moved (the Chinese dragon at 10 %: a worst aspect ratio of 7,949 by thesis eq.
// 4.2, 152 with the floor; Blender's Decimate 831). The limit of half of it for already thin
// triangles keeps the freedom CAD meshes' long strips need (without it, the coupling at 10 % had
// twice the mean error).
double Collapser::shape_floor2(int32_t v) const {
  double floor2 = std::numeric_limits<double>::infinity();
  int32_t thinnest = -1;
  for (const int32_t* t = faces_begin(v); t != faces_end(v); ++t)
    if (const double s = shape2(*t); s < floor2) floor2 = s, thinnest = *t;
  if (tracking_floors_ && size_[v] > kWideFan) floor_bound_[v].set(floor2), floor_witness_[v].set(thinnest);
  return std::min(floor2, min_shape_ * min_shape_);
}

// The squared shape quality of live triangle t, 12 |n|^2 / (sum of squared edges)^2, or infinity
// for a degenerate one (shape_floor2 leaves those out).
double Collapser::shape2(int32_t t) const {
  const int32_t* c = &(*tri_)[3 * size_t(t)];
  double n[3];
  const double area2 = face_normal2(t, n), edges = squared_edges(c, c[0], position(c[0]));
  return area2 > 0.0 && edges > 0.0 ? 12.0 * area2 / (edges * edges) : std::numeric_limits<double>::infinity();
}

// Triangle t changed (a corner moved or was renamed): a wide corner's bound drops to its shape if
// that is lower, so that the bound stays at or below the corner's floor.
void Collapser::lower_floor_bounds(int32_t t) {
  const int32_t* c = &(*tri_)[3 * size_t(t)];
  double value = -1.0;
  for (int j = 0; j < 3; ++j) {
    star_face_changed(c[j], t);
    const double bound = floor_bound_[c[j]].get();
    if (bound < 0.0) continue;
    if (value < 0.0) value = shape2(t);
    if (value < bound) floor_bound_[c[j]].set(value);
  }
}

// Every triangle of v changed (v moved): v's own bound is dropped, its corners' lowered.
void Collapser::moved_floor_bounds(int32_t v) {
  if (!tracking_floors_) return;
  floor_bound_[v].set(-1.0);
  for (const int32_t* t = faces_begin(v); t != faces_end(v); ++t) lower_floor_bounds(*t);
}

// Do the triangles of `moved` that do not hold `other` keep their side and some area when
// `moved` stands at x (other = -1: all of them)?
bool Collapser::keeps_shape(int32_t moved, int32_t other, const double* x, ShapeFloor& floor) const {
  if (!shape_checks_) return true;
  // A wide vertex that stays where it is leaves its other triangles as they were (a half-edge
  // collapse onto a fan's centre: the walk compared each of its triangles with itself).
  if (const double* p = position(moved); size_[moved] > kWideFan && x[0] == p[0] && x[1] == p[1] && x[2] == p[2])
    return true;
  if (other >= 0 && size_[moved] > kWideFan && !beside_edge_keep_shape(moved, other, x, floor)) return false;
  for (const int32_t* t = faces_begin(moved); t != faces_end(moved); ++t)
    if ((other < 0 || !has(*t, other)) && !keeps_face_shape(*t, moved, x, floor)) return false;
  return true;
}

// keeps_shape's test first on the triangles of a wide `moved` beside the edge (those holding a
// vertex opposite it), found from the opposite vertices' faces: where a fan's collapse fails,
// these fail first (they are the ones squeezed), without the walk of the fan.
bool Collapser::beside_edge_keep_shape(int32_t moved, int32_t other, const double* x, ShapeFloor& floor) const {
  for (const int32_t* e = faces_begin(other); e != faces_end(other); ++e) {
    if (!has(*e, moved)) continue;
    const int32_t* c = &(*tri_)[3 * size_t(*e)];
    const int32_t o = c[0] != moved && c[0] != other ? c[0] : c[1] != moved && c[1] != other ? c[1] : c[2];
    if (size_[o] > kWideFan) continue;
    for (const int32_t* t = faces_begin(o); t != faces_end(o); ++t)
      if (has(*t, moved) && !has(*t, other) && !keeps_face_shape(*t, moved, x, floor)) return false;
  }
  return true;
}

// Does triangle t of `moved` keep its side and some area, and not become a sliver, with `moved` at x?
bool Collapser::keeps_face_shape(int32_t t, int32_t moved, const double* x, ShapeFloor& floor) const {
  const double* p = position(moved);
  const int32_t* c = &(*tri_)[3 * size_t(t)];
  double before[3], after[3];
  normal(c, moved, p, before);
  normal(c, moved, x, after);
  double before2 = before[0] * before[0] + before[1] * before[1] + before[2] * before[2];
  const double area2 = before2;
  if (before2 == 0.0) {
    // A zero-area triangle has no side to keep. Staying degenerate is no worse (collapsing
    // coincident vertices one by one is how a fan of them disappears); gaining area, it
    // must face like the fan.
    if (after[0] == 0.0 && after[1] == 0.0 && after[2] == 0.0) return true;
    for (int i = 0; i < 3; ++i) before[i] = 0.0;
    for (const int32_t* f = faces_begin(moved); f != faces_end(moved); ++f) {
      double n[3];
      normal(&(*tri_)[3 * size_t(*f)], moved, p, n);
      for (int i = 0; i < 3; ++i) before[i] += n[i];
    }
    before2 = before[0] * before[0] + before[1] * before[1] + before[2] * before[2];
  }
  const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
  const double len2 = after[0] * after[0] + after[1] * after[1] + after[2] * after[2];
  // No flip, no near-fold (normal turned by more than the limit, ~80 degrees), no loss of area.
  if (!(dot > 0.0) || dot * dot <= fold2_ * len2 * before2 || len2 <= 1e-24 * before2) return false;
  // No sliver: not thinner than the floor (at most kMinShape), unless the triangle was
  // thinner than kMinShape already and stays within half of it.
  const double edges = squared_edges(c, moved, x);
  if (!thinner(len2, edges, min_shape_ * min_shape_)) return true;
  // In a flat region (the moved vertex's triangles in one plane, this one keeping it) a needle as
  // thin as the input's costs nothing (CollapseSetup::input_floor2).
  bool flat = false;
  if (!s_.input_floor2.empty() && dot * dot >= (1.0 - kFlatTurn2) * len2 * before2) {
    if (floor.flat < 0) floor.flat = flat_star(moved);
    flat = floor.flat;
  }
  return !((!thinner(area2, squared_edges(c, moved, p), min_shape_ * min_shape_) ||
            thinner(len2, edges, 0.25 * min_shape_ * min_shape_)) &&
           below_floor(len2, edges, flat, floor));
}

// Whether v's live triangles with area all face one way (normals within kFlatTurn2); kept for a
// wide v (flat_star_).
bool Collapser::flat_star(int32_t v) const {
  if (tracking_floors_ && size_[v] > kWideFan) {
    int8_t known = flat_star_[v].get();
    if (known < 0) {
      int32_t first = -1;
      known = walk_flat_star(v, &first);
      flat_reference_[v].set(first);
      flat_star_[v].set(known);
    }
    return known;
  }
  return walk_flat_star(v);
}

// flat_star by a walk of v's triangles, each compared with the first with area (*reference;
// -1: none has area).
bool Collapser::walk_flat_star(int32_t v, int32_t* reference) const {
  int32_t first = -1;
  double a[3], a2 = 0.0;
  for (const int32_t* t = faces_begin(v); t != faces_end(v); ++t) {
    double n[3];
    const double n2 = face_normal2(*t, n);
    if (!(n2 > 0.0)) continue;
    if (first < 0) {
      first = *t, a2 = n2;
      for (int i = 0; i < 3; ++i) a[i] = n[i];
    } else if (apart(a, a2, n, n2)) {
      return false;
    }
  }
  if (reference) *reference = first;
  return true;
}

// Triangle t's unnormalised normal into n; returns its squared length.
double Collapser::face_normal2(int32_t t, double n[3]) const {
  const int32_t* c = &(*tri_)[3 * size_t(t)];
  normal(c, c[0], position(c[0]), n);
  return n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
}

// Triangle t of wide v's star changed (a corner moved or was renamed, or it was added at the end
// of v's list): v's kept flatness (flat_star_) is updated without a walk where t alone decides it.
// A flat star stays flat unless t is its first triangle with area or now faces apart from it; a
// star found not flat is walked again.
void Collapser::star_face_changed(int32_t v, int32_t t) {
  if (flat_star_[v].get() != 1) return flat_star_[v].set(-1);
  const int32_t first = flat_reference_[v].get();
  if (t == first) return flat_star_[v].set(-1);
  double n[3];
  const double n2 = face_normal2(t, n);
  if (!(n2 > 0.0)) return;                      // no area: the walk skips it
  if (first < 0) return flat_star_[v].set(-1);  // t is now the first with area
  const int32_t* f = faces_begin(v);
  for (; f != faces_end(v) && *f != first; ++f)
    if (*f == t) return flat_star_[v].set(-1);  // t comes before the first: now it is
  if (f == faces_end(v)) return flat_star_[v].set(-1);
  double a[3];
  const double a2 = face_normal2(first, a);
  if (apart(a, a2, n, n2)) flat_star_[v].set(0);
}

// Is a triangle thinner than the floor of the move, the lower of its ends' floors? Thinner than
// both, that is: the end with fewer faces is read first, and the other only when needed.
bool Collapser::below_floor(double twice_area2, double edges, bool flat, ShapeFloor& floor) const {
  int32_t first = floor.a, second = floor.b;
  double *first2 = &floor.a2, *second2 = &floor.b2;
  if (second >= 0 && size_[second] < size_[first]) std::swap(first, second), std::swap(first2, second2);
  if (!below_end_floor(twice_area2, edges, flat, first, *first2)) return false;
  return second < 0 || below_end_floor(twice_area2, edges, flat, second, *second2);
}

// Thinner than end v's floor (floor2, read once: -1 until then)? A wide end's kept bound, at or
// below its floor, answers yes without the walk of its faces when the triangle is thinner still.
bool Collapser::below_end_floor(double twice_area2, double edges, bool flat, int32_t v, double& floor2) const {
  if (!s_.input_floor2.empty() && (flat || !s_.input_floor_flat_only) && size_[v] <= kWideFan &&
      !thinner(twice_area2, edges, s_.input_floor2[v]))
    return false;  // no thinner than the input's thinnest where v stands (CollapseSetup::input_floor2)
  if (floor2 < 0.0) {
    const double bound = floor_bound_.empty() ? -1.0 : floor_bound_[v].get();
    if (bound >= 0.0 && thinner(twice_area2, edges, std::min(bound, min_shape_ * min_shape_))) return true;
    const int32_t witness = floor_witness_.empty() ? -1 : floor_witness_[v].get();
    if (witness >= 0 && alive_face_[witness] && has(witness, v) &&
        !thinner(twice_area2, edges, std::min(shape2(witness), min_shape_ * min_shape_)))
      return false;  // no thinner than one of v's triangles: not below v's floor
    floor2 = shape_floor2(v);
  }
  return thinner(twice_area2, edges, floor2);
}

// Shape quality 2 sqrt(3) |n| / (sum of squared edges) of triangle c with `replace` at `at`
// (|n| = twice its area): 1 for an equilateral triangle, 0 for a degenerate one.
double Collapser::shape(const int32_t* c, int32_t replace, const double* at, double twice_area) const {
  const double edges = squared_edges(c, replace, at);
  return edges > 0 ? 2.0 * std::sqrt(3.0) * twice_area / edges : 0.0;
}

double Collapser::squared_edges(const int32_t* c, int32_t replace, const double* at) const {
  const double* p[3];
  for (int j = 0; j < 3; ++j) p[j] = c[j] == replace ? at : position(c[j]);
  double edges = 0;
  for (int j = 0; j < 3; ++j) {
    const double* a = p[j];
    const double* b = p[j == 2 ? 0 : j + 1];
    edges += (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
  }
  return edges;
}

// Normal (unnormalised) of triangle c with vertex `replace` standing at `at`.
void Collapser::normal(const int32_t* c, int32_t replace, const double* at, double n[3]) const {
  const double* p[3];
  for (int j = 0; j < 3; ++j) p[j] = c[j] == replace ? at : position(c[j]);
  double a[3], b[3];
  for (int i = 0; i < 3; ++i) a[i] = p[1][i] - p[0][i], b[i] = p[2][i] - p[0][i];
  n[0] = a[1] * b[2] - a[2] * b[1], n[1] = a[2] * b[0] - a[0] * b[2], n[2] = a[0] * b[1] - a[1] * b[0];
}

void Collapser::move_to(int32_t v, const double* x) {
  double* p = &s_.positions[3 * size_t(v)];
  double* w = &s_.world[3 * size_t(v)];
  bool moved = false;
  for (int i = 0; i < 3; ++i) {
    if (p[i] == x[i]) continue;  // unmoved coordinates keep their exact input value
    p[i] = x[i];
    w[i] = x[i] * s_.extent + s_.center[i];
    moved = true;
  }
  if (moved) changed(v), moved_floor_bounds(v), span_moved(v);
}

void Collapser::collapse(int32_t u, int32_t v) {
  last_removed_ = u;
  if (!s_.input_floor2.empty()) s_.input_floor2[v] = std::min(s_.input_floor2[v], s_.input_floor2[u]);
  {
    double x[3];
    if (rescue_) {
      placed_[v] = shaped_placement(u, v, x) == 1;
    } else {
      Quadric q;
      s_.quadrics.reduced(u, v, q);
      placed_[v] = placement(u, v, q, x);
    }
    move_to(v, x);
  }
  // The triangles on the edge vanish. On each side of u's borders (each sheet of a non-manifold
  // curve) one of them had a corner at v: u's other triangles on that side take that corner (and
  // its sector) where they meet v.
  struct Side {
    int32_t sector, corner, corner_sector;
  };
  Side sides[kMaxSheets];
  int32_t num_sides = 0;
  for (const int32_t* t = faces_begin(u); t != faces_end(u); ++t) {
    if (!has(*t, v)) continue;
    alive_face_[*t] = 0;
    --alive_faces_;
    Side side{sector_at(*t, u), -1, -1};
    for (int j = 0; j < 3; ++j) {
      const int32_t w = (*tri_)[3 * size_t(*t) + j];
      if (w == v) side.corner = (*corner_source_)[3 * size_t(*t) + j], side.corner_sector = s_.corner_sector[3 * size_t(*t) + j];
      if (w != u) remove_face(w, *t);
    }
    sides[num_sides++] = side;
  }
  const bool dead_end = is_dead_end(u);
  moved_faces_.clear();
  for (const int32_t* t = faces_begin(u); t != faces_end(u); ++t) {
    if (!alive_face_[*t]) continue;
    for (int j = 0; j < 3; ++j)
      if ((*tri_)[3 * size_t(*t) + j] == u) {
        const size_t corner = 3 * size_t(*t) + j;
        const Side* side = &sides[0];
        for (int32_t i = 1; i < num_sides; ++i)
          if (s_.corner_sector[corner] == sides[i].sector) side = &sides[i];
        (*tri_)[corner] = v;
        (*corner_source_)[corner] = side->corner;
        s_.corner_sector[corner] = side->corner_sector;
      }
    moved_faces_.push_back(*t);
  }
  append_faces(v, moved_faces_.data(), static_cast<int32_t>(moved_faces_.size()));
  if (tracking_floors_)
    for (int32_t t : moved_faces_) lower_floor_bounds(t);
  if (dead_end) {
    // Each sheet around the dead end held two of the edge's triangles, one on each side of the
    // curve at v: with u gone the curve ends at v, and each sheet's two sides there are one.
    int32_t from[kMaxSheets], to[kMaxSheets], pairs = 0;
    for (int32_t i = 0; i < num_sides; ++i)
      for (int32_t j = i + 1; j < num_sides; ++j)
        if (sides[i].sector == sides[j].sector) from[pairs] = sides[i].corner_sector, to[pairs++] = sides[j].corner_sector;
    merge_sides(v, from, to, pairs);
    s_.dead_end[u] = 0;
    s_.dead_end[v] = !s_.locked[v];
  }
  if (s_.curve[u] >= 0) --s_.curve_size[s_.curve[u]];
  unlink_span(u);
  --count_[s_.bin[u]];
  --alive_vertices_;
  size_[u] = 0;
  merged_into_[u] = v;
  s_.quadrics.merge(v, u);
  changed(v);
  heap_.remove(u);
  target_[u] = -1;
  merged_from_[v] = u;
}

// Renames v's corner sectors from[i] to to[i] (the moved triangles took the side of to[i]).
void Collapser::merge_sides(int32_t v, const int32_t* from, const int32_t* to, int32_t count) {
  for (const int32_t* t = faces_begin(v); t != faces_end(v); ++t)
    for (int j = 0; j < 3; ++j) {
      const size_t corner = 3 * size_t(*t) + j;
      if ((*tri_)[corner] != v) continue;
      for (int32_t i = 0; i < count; ++i)
        if (s_.corner_sector[corner] == from[i]) {
          s_.corner_sector[corner] = to[i];
          break;
        }
    }
}

// After collapsing u into v, alone: v's collapses all change (its quadric grew, it may have
// moved); each neighbour is offered the collapse onto v.
void Collapser::refresh(int32_t u, int32_t v) {
  Scratch& scratch = scratch_[0];
  neighbours(v, scratch, star_);
  const bool v_queues = queues(v);
  Best best;
  for (int32_t x : star_) {
    // An edge between free vertices costs the same both ways: one evaluation serves both.
    const double to_x = v_queues ? cost(v, x) : 0.0;
    if (v_queues && (best.target < 0 || to_x < best.cost || (to_x == best.cost && x < best.target))) best = {x, to_x};
    if (queues(x)) offer(x, v, u, v_queues && free_pair(x, v) ? to_x : cost(x, v));
  }
  settle(v, best);
}

int32_t Collapser::refit(const std::vector<double>& radius2) {
  // Targets in parallel (they depend on each vertex's own quadric only), moves in order (a
  // move's checks see the neighbours already moved).
  const int32_t n = static_cast<int32_t>(merged_into_.size());
  std::vector<double> goal(3 * size_t(n));
  std::vector<uint8_t> better(n, 0);
  parallel_for(0, n, 10000, [&](int32_t v) {
    // A vertex a collapse put at its quadric's minimum is there already.
    if (merged_into_[v] >= 0 || !is_free(v) || size_[v] == 0 || placed_[v]) return;
    Quadric q;
    s_.quadrics.reduced(v, -1, q);
    const double* p = position(v);
    double step[3];
    if (!q.truncated_step(p, step)) return;
    const double len2 = step[0] * step[0] + step[1] * step[1] + step[2] * step[2];
    if (!(len2 > 0)) return;
    const double scale = len2 > radius2[v] ? std::sqrt(radius2[v] / len2) : 1.0;
    double* x = &goal[3 * size_t(v)];
    for (int i = 0; i < 3; ++i) x[i] = p[i] + scale * step[i];
    better[v] = q.error(x) < q.error(p);
  });
  int32_t moved = 0;
  for (int32_t v = 0; v < n; ++v) moved += better[v] && try_move(v, &goal[3 * size_t(v)]);
  return moved;
}

bool Collapser::try_move(int32_t v, const double* x) {
  ShapeFloor floor{v, -1};
  if (!keeps_shape(v, -1, x, floor)) return false;
  move_to(v, x);
  return true;
}

void Collapser::restore(int32_t v, const double* position, const double* world) {
  for (int i = 0; i < 3; ++i) s_.positions[3 * size_t(v) + i] = position[i], s_.world[3 * size_t(v) + i] = world[i];
  changed(v);
  moved_floor_bounds(v);
  span_moved(v);
}

}  // namespace topstoc
