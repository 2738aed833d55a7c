#include "topstoc/decimate/refine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "decimate/indexed_heap.hpp"
#include "topstoc/decimate/quadric.hpp"

namespace topstoc {

namespace {

// Collapses may not make a triangle thinner than this shape quality (see Collapser::shape;
// 0.1 is an aspect ratio of about 5-10 by the thesis' measure) unless it already was.
constexpr double kMinShape = 0.1;

class Collapser {
 public:
  // curve: per output vertex, the feature curve it lies on (it may then move only along it), or
  // -1; corner_sector: per output corner, the sector (side of the borders) of its vertex.
  Collapser(DecimateResult& result, std::vector<Quadric> quadrics, std::vector<double> weight,
            std::vector<uint8_t> locked, std::vector<int32_t> curve, std::vector<int32_t> curve_size,
            std::vector<uint8_t> curve_closed, std::vector<int32_t> corner_sector, std::vector<int32_t> bin,
            std::vector<int32_t> quota)
      : r_(result), quadric_(std::move(quadrics)), weight_(std::move(weight)), locked_(std::move(locked)),
        curve_(std::move(curve)), curve_size_(std::move(curve_size)), curve_closed_(std::move(curve_closed)),
        corner_sector_(std::move(corner_sector)), bin_(std::move(bin)), quota_(std::move(quota)),
        heap_(static_cast<int32_t>(result.kept.size())) {
    const size_t n = r_.kept.size(), m = r_.face_source.size();
    count_.assign(quota_.size(), 0);
    alive_vertices_ = static_cast<int32_t>(n);
    for (int32_t b : bin_) ++count_[b];
    vertex_faces_.resize(n);
    for (size_t t = 0; t < m; ++t)
      for (int j = 0; j < 3; ++j) vertex_faces_[r_.triangles[3 * t + j]].push_back(int32_t(t));
    alive_face_.assign(m, 1);
    merged_into_.assign(n, -1);
    target_.assign(n, -1);
    for (int32_t u = 0; u < int32_t(n); ++u) update(u);
  }

  /// Collapses an edge of every zero-area triangle where a collapse is allowed (the triangle
  /// and its neighbour across the edge vanish; no collapse creates a new one). Returns the
  /// collapses made.
  int32_t remove_zero_area(double min_shape = 0.0, int32_t keep = 0) {
    int32_t collapses = 0;
    for (bool progress = true; progress;) {
      progress = false;
      for (size_t t = 0; t < alive_face_.size(); ++t) {
        if (alive_vertices_ <= keep) return collapses;
        if (!alive_face_[t] || !(zero_area(int32_t(t)) || thin(int32_t(t), min_shape))) continue;
        const int32_t* c = &r_.triangles[3 * t];
        for (int j = 0; j < 6; ++j) {
          const int32_t u = c[j % 3], v = c[(j % 3 + (j < 3 ? 1 : 2)) % 3];
          if (locked_[u] || !allowed(u, v)) continue;
          collapse(u, v);
          ++collapses;
          progress = true;
          break;
        }
      }
    }
    return collapses;
  }

  int32_t zero_area_faces() const {
    int32_t count = 0;
    for (size_t t = 0; t < alive_face_.size(); ++t) count += alive_face_[t] && zero_area(int32_t(t));
    return count;
  }

  /// Collapses until `target` vertices remain or no collapse is allowed; returns the count.
  int32_t run(int32_t target) {
    int32_t collapses = 0;
    for (;;) {
      if (alive_vertices_ <= target) break;
      if (heap_.empty()) {
        // Some region could not reach its quota: the others give the rest, by cost alone.
        if (!use_quota_) break;
        use_quota_ = false;
        for (int32_t u = 0; u < int32_t(merged_into_.size()); ++u)
          if (merged_into_[u] < 0) update(u);
        continue;
      }
      const int32_t u = heap_.top(), v = target_[u];
      if (at_quota(u)) {
        target_[u] = -1;
        heap_.remove(u);
        continue;
      }
      // Collapses next to `v` may have changed its cost or ruled it out: look again.
      if (merged_into_[v] >= 0 || heap_.top_key() != cost(u, v)) {
        update(u);
        continue;
      }
      if (!allowed(u, v)) {
        update(u, true);
        continue;
      }
      collapse(u, v);
      ++collapses;
    }
    return collapses;
  }

  /// Compacts the result: surviving vertices and faces in their old order, labels followed
  /// along the collapses.
  void write_back() {
    const int32_t n = static_cast<int32_t>(r_.kept.size());
    std::vector<int32_t> new_index(n, -1);
    int32_t next = 0;
    for (int32_t v = 0; v < n; ++v)
      if (merged_into_[v] < 0) {
        new_index[v] = next;
        r_.kept[next] = r_.kept[v];
        for (int i = 0; i < 3; ++i) r_.vertices[3 * size_t(next) + i] = r_.vertices[3 * size_t(v) + i];
        ++next;
      }
    r_.kept.resize(next);
    r_.vertices.resize(3 * size_t(next));
    size_t faces = 0;
    for (size_t t = 0; t < alive_face_.size(); ++t) {
      if (!alive_face_[t]) continue;
      for (int j = 0; j < 3; ++j) {
        r_.triangles[3 * faces + j] = new_index[r_.triangles[3 * t + j]];
        r_.corner_source[3 * faces + j] = r_.corner_source[3 * t + j];
      }
      r_.face_source[faces] = r_.face_source[t];
      ++faces;
    }
    r_.triangles.resize(3 * faces);
    r_.corner_source.resize(3 * faces);
    r_.face_source.resize(faces);
    for (auto& label : r_.labels)
      if (label >= 0) label = new_index[survivor(label)];
  }

 private:
  // Both ends free (off every border curve, not locked): the edge collapses to the point that
  // minimises the summed quadric; otherwise `from` moves onto `to` (half-edge collapse), so
  // border vertices stay input vertices on their curve.
  bool free_pair(int32_t from, int32_t to) const {
    return optimal_placement && curve_[from] < 0 && curve_[to] < 0 && !locked_[to] && !locked_[from];
  }

  // Where the collapse of `from` into `to` puts the survivor.
  void placement(int32_t from, int32_t to, double x[3]) const {
    const double* pt = &r_.vertices[3 * size_t(to)];
    for (int i = 0; i < 3; ++i) x[i] = pt[i];
    if (!free_pair(from, to)) return;
    Quadric q = quadric_[from];
    q.add(quadric_[to]);
    const double* pf = &r_.vertices[3 * size_t(from)];
    double d[3], length2 = 0;
    for (int i = 0; i < 3; ++i) d[i] = pt[i] - pf[i], length2 += d[i] * d[i];
    if (q.minimum(x)) {
      // Trust the optimum only near the edge (a nearly flat or straight neighbourhood makes it
      // drift along the surface).
      double far2 = 0;
      for (int i = 0; i < 3; ++i) far2 += (x[i] - 0.5 * (pf[i] + pt[i])) * (x[i] - 0.5 * (pf[i] + pt[i]));
      if (far2 <= length2) return;
    }
    // The best point on the edge: E(pf + t d) is quadratic in t.
    const double t = std::clamp(q.line_minimum(pf, d), 0.0, 1.0);
    for (int i = 0; i < 3; ++i) x[i] = pf[i] + t * d[i];
  }

  double cost(int32_t from, int32_t to) const {
    double x[3];
    placement(from, to, x);
    const double w = free_pair(from, to) ? std::max(weight_[from], weight_[to]) : weight_[from];
    return w * std::max(0.0, quadric_[from].error(x) + quadric_[to].error(x));
  }

  // Queues u's cheapest collapse. Checks wait until it is popped (most queued collapses are
  // superseded before that); with `checked`, the cheapest one that passes them. None: u
  // waits until a collapse next to it calls update again.
  void update(int32_t u, bool checked = false) {
    target_[u] = -1;
    heap_.remove(u);
    if (locked_[u] || at_quota(u)) return;
    neighbours(u, options_);
    if (!checked) {  // the cheapest, lowest id on ties
      int32_t best = -1;
      double best_cost = 0;
      for (int32_t v : options_) {
        const double c = cost(u, v);
        if (best < 0 || c < best_cost) best = v, best_cost = c;
      }
      if (best >= 0) queue(u, best, best_cost);
      return;
    }
    costs_.clear();
    for (int32_t v : options_) costs_.push_back({cost(u, v), v});
    std::sort(costs_.begin(), costs_.end());
    for (const auto& [c, v] : costs_)
      if (allowed(u, v)) {
        queue(u, v, c);
        return;
      }
  }

  bool thin(int32_t t, double min_shape) const {
    if (min_shape <= 0.0) return false;
    double n[3];
    const int32_t* c = &r_.triangles[3 * size_t(t)];
    normal(c, c[0], &r_.vertices[3 * size_t(c[0])], n);
    return shape(c, c[0], &r_.vertices[3 * size_t(c[0])], std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])) <
           min_shape;
  }

  bool zero_area(int32_t t) const {
    double n[3];
    const int32_t* c = &r_.triangles[3 * size_t(t)];
    normal(c, c[0], &r_.vertices[3 * size_t(c[0])], n);
    return n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0;
  }

  bool at_quota(int32_t u) const { return use_quota_ && count_[bin_[u]] <= quota_[bin_[u]]; }

  void queue(int32_t u, int32_t v, double c) {
    target_[u] = v;
    heap_.set(u, c);
  }

  int32_t survivor(int32_t v) {
    int32_t root = v;
    while (merged_into_[root] >= 0) root = merged_into_[root];
    while (merged_into_[v] >= 0) {
      const int32_t up = merged_into_[v];
      merged_into_[v] = root;
      v = up;
    }
    return root;
  }

  void neighbours(int32_t v, std::vector<int32_t>& out) const {
    out.clear();
    for (int32_t t : vertex_faces_[v])
      for (int j = 0; j < 3; ++j)
        if (r_.triangles[3 * size_t(t) + j] != v) out.push_back(r_.triangles[3 * size_t(t) + j]);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  bool has(int32_t t, int32_t v) const {
    const int32_t* c = &r_.triangles[3 * size_t(t)];
    return c[0] == v || c[1] == v || c[2] == v;
  }

  int32_t sector_at(int32_t t, int32_t v) const {
    for (int j = 0; j < 3; ++j)
      if (r_.triangles[3 * size_t(t) + j] == v) return corner_sector_[3 * size_t(t) + j];
    return -1;
  }

  // Link condition (Dey et al. 1999): u and v share exactly the vertices opposite their edge,
  // and v keeps at least three neighbours; then the surface stays a manifold of the same
  // topology. An interior u may go to any neighbour; a u on a border curve only along the
  // curve (the edge must separate u's sectors, or be a boundary edge), so every border keeps
  // its course and its sides.
  bool allowed(int32_t u, int32_t v) {
    std::vector<int32_t>& nu = scratch_;
    std::vector<int32_t>& nv = scratch_other_;
    neighbours(u, nu);
    if (!std::binary_search(nu.begin(), nu.end(), v)) return false;
    int32_t on_edge[2], count = 0;
    for (int32_t t : vertex_faces_[u])
      if (has(t, v)) {
        if (count == 2) return false;
        on_edge[count++] = t;
      }
    const bool closed_fan = nu.size() == vertex_faces_[u].size();
    if (curve_[u] < 0) {
      if (!closed_fan || count != 2) return false;
    } else {
      if (curve_[v] != curve_[u] && !locked_[v]) return false;
      const bool boundary_edge = count == 1 && nu.size() == vertex_faces_[u].size() + 1;
      const bool border_edge = count == 2 && closed_fan && sector_at(on_edge[0], u) != sector_at(on_edge[1], u);
      if (!boundary_edge && !border_edge) return false;
      if (curve_closed_[curve_[u]] && curve_size_[curve_[u]] <= 3) return false;
    }
    neighbours(v, nv);
    int32_t shared = 0;
    for (size_t i = 0, j = 0; i < nu.size() && j < nv.size();) {
      if (nu[i] < nv[j]) {
        ++i;
      } else if (nu[i] > nv[j]) {
        ++j;
      } else {
        ++shared, ++i, ++j;
      }
    }
    if (shared != count) return false;
    if (nu.size() + nv.size() < size_t(shared) + 5) return false;  // v would keep < 3 neighbours
    double x[3];
    placement(u, v, x);
    return keeps_shape(u, v, x) && keeps_shape(v, u, x);
  }

  // Do the triangles of `moved` that do not hold `other` keep their side and some area when
  // `moved` stands at x?
  bool keeps_shape(int32_t moved, int32_t other, const double* x) const {
    // A zero-area triangle has no side to keep: it must gain area facing like the fan.
    double fan[3] = {0, 0, 0};
    for (int32_t t : vertex_faces_[moved]) {
      double n[3];
      normal(&r_.triangles[3 * size_t(t)], moved, &r_.vertices[3 * size_t(moved)], n);
      for (int i = 0; i < 3; ++i) fan[i] += n[i];
    }
    for (int32_t t : vertex_faces_[moved]) {
      if (has(t, other)) continue;
      const int32_t* c = &r_.triangles[3 * size_t(t)];
      double before[3], after[3];
      normal(c, moved, &r_.vertices[3 * size_t(moved)], before);
      normal(c, moved, x, after);
      double before2 = before[0] * before[0] + before[1] * before[1] + before[2] * before[2];
      if (before2 == 0.0) {
        for (int i = 0; i < 3; ++i) before[i] = fan[i];
        before2 = fan[0] * fan[0] + fan[1] * fan[1] + fan[2] * fan[2];
      }
      const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
      const double len2 = after[0] * after[0] + after[1] * after[1] + after[2] * after[2];
      // No flip, no near-fold (normal turned by more than ~80 degrees), no loss of area.
      if (!(dot > 0.17 * std::sqrt(len2 * before2)) || len2 <= 1e-24 * before2) return false;
      // No sliver: a triangle may not end up thinner than kMinShape unless it was already.
      if (shape(c, moved, x, std::sqrt(len2)) < kMinShape &&
          shape(c, moved, &r_.vertices[3 * size_t(moved)], std::sqrt(before2)) >= kMinShape)
        return false;
    }
    return true;
  }

  // Shape quality 2 sqrt(3) |n| / (sum of squared edges) of triangle c with `replace` at `at`
  // (|n| = twice its area): 1 for an equilateral triangle, 0 for a degenerate one.
  double shape(const int32_t* c, int32_t replace, const double* at, double twice_area) const {
    const double* p[3];
    for (int j = 0; j < 3; ++j) p[j] = c[j] == replace ? at : &r_.vertices[3 * size_t(c[j])];
    double edges = 0;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) edges += (p[j][i] - p[(j + 1) % 3][i]) * (p[j][i] - p[(j + 1) % 3][i]);
    return edges > 0 ? 2.0 * std::sqrt(3.0) * twice_area / edges : 0.0;
  }

  // Normal (unnormalised) of triangle c with vertex `replace` standing at `at`.
  void normal(const int32_t* c, int32_t replace, const double* at, double n[3]) const {
    const double* p[3];
    for (int j = 0; j < 3; ++j) p[j] = c[j] == replace ? at : &r_.vertices[3 * size_t(c[j])];
    double a[3], b[3];
    for (int i = 0; i < 3; ++i) a[i] = p[1][i] - p[0][i], b[i] = p[2][i] - p[0][i];
    n[0] = a[1] * b[2] - a[2] * b[1], n[1] = a[2] * b[0] - a[0] * b[2], n[2] = a[0] * b[1] - a[1] * b[0];
  }

  void collapse(int32_t u, int32_t v) {
    double x[3];
    placement(u, v, x);
    for (int i = 0; i < 3; ++i) r_.vertices[3 * size_t(v) + i] = x[i];
    // The triangles on the edge vanish. On each side of u's borders one of them had a corner at
    // v: u's other triangles on that side take that corner (and its sector) where they meet v.
    struct Side {
      int32_t sector, corner, corner_sector;
    };
    Side sides[2];
    int32_t num_sides = 0;
    for (int32_t t : vertex_faces_[u]) {
      if (!has(t, v)) continue;
      alive_face_[t] = 0;
      Side side{sector_at(t, u), -1, -1};
      for (int j = 0; j < 3; ++j) {
        const int32_t w = r_.triangles[3 * size_t(t) + j];
        if (w == v) side.corner = r_.corner_source[3 * size_t(t) + j], side.corner_sector = corner_sector_[3 * size_t(t) + j];
        if (w == u) continue;
        auto& list = vertex_faces_[w];
        list.erase(std::find(list.begin(), list.end(), t));
      }
      sides[num_sides++] = side;
    }
    for (int32_t t : vertex_faces_[u]) {
      if (!alive_face_[t]) continue;
      for (int j = 0; j < 3; ++j)
        if (r_.triangles[3 * size_t(t) + j] == u) {
          const Side& side = (num_sides == 2 && corner_sector_[3 * size_t(t) + j] == sides[1].sector) ? sides[1] : sides[0];
          r_.triangles[3 * size_t(t) + j] = v;
          r_.corner_source[3 * size_t(t) + j] = side.corner;
          corner_sector_[3 * size_t(t) + j] = side.corner_sector;
        }
      vertex_faces_[v].push_back(t);
    }
    if (curve_[u] >= 0) --curve_size_[curve_[u]];
    --count_[bin_[u]];
    --alive_vertices_;
    vertex_faces_[u].clear();
    merged_into_[u] = v;
    quadric_[v].add(quadric_[u]);
    heap_.remove(u);
    // v's costs all change (its quadric grew); around it only collapses onto v or u change,
    // or a new edge to v may be cheaper than what a vertex had queued. Checks that failed
    // may pass now: a vertex without a queued collapse looks again.
    update(v);
    neighbours(v, star_);
    for (int32_t x : star_) {
      if (locked_[x] || at_quota(x)) continue;
      if (target_[x] < 0 || target_[x] == u || target_[x] == v) {
        update(x);
      } else {
        const double c = cost(x, v);
        if (c < heap_.key_of(x)) queue(x, v, c);
      }
    }
  }

  DecimateResult& r_;
  std::vector<Quadric> quadric_;
  std::vector<double> weight_;
  std::vector<uint8_t> locked_;
  std::vector<int32_t> curve_, curve_size_;
  std::vector<uint8_t> curve_closed_;
  std::vector<int32_t> corner_sector_;
  std::vector<int32_t> bin_, quota_, count_;  // per vertex its guidance bin; per bin quota, alive count
  bool use_quota_ = true;
  int32_t alive_vertices_ = 0;

 public:
  bool optimal_placement = true;  // off: every collapse is a half-edge collapse (positions kept)

 private:
  std::vector<std::vector<int32_t>> vertex_faces_;
  std::vector<uint8_t> alive_face_;
  std::vector<int32_t> merged_into_, target_;
  IndexedHeap heap_;
  std::vector<int32_t> scratch_, scratch_other_, options_, star_;
  std::vector<std::pair<double, int32_t>> costs_;
};

// Guidance bins: 0 for m = 0 (never sampled), 1 for control points, then m on a quarter-octave
// scale.
constexpr int32_t kBins = 2 + 81;
int32_t guidance_bin(double m) {
  if (m == kForcedMultiplier) return 1;
  if (m <= 0.0) return 0;
  return 2 + 40 + std::clamp(int32_t(std::lround(4.0 * std::log2(m))), -40, 40);
}

// Vertex quota per bin (see RefineParams): sum over the bin's vertices of min(1, k m), k solved
// so the quotas sum to `target`, rounded by largest remainder.
std::vector<int32_t> bin_quotas(const std::vector<double>& vertices, const std::vector<double>& multiplier_sum,
                                int32_t target) {
  const int32_t bins = int32_t(vertices.size());
  std::vector<double> mean(bins, 0.0);
  for (int32_t b = 2; b < bins; ++b) mean[b] = vertices[b] > 0 ? multiplier_sum[b] / vertices[b] : 0.0;
  auto total = [&](double k) {
    double sum = vertices[1];
    for (int32_t b = 2; b < bins; ++b) sum += vertices[b] * std::min(1.0, k * mean[b]);
    return sum;
  };
  std::vector<double> exact(bins, 0.0);
  exact[1] = std::min<double>(vertices[1], target);
  if (vertices[1] < target) {
    double lo = 0.0, hi = 1.0;
    while (total(hi) < target && hi < 1e30) hi *= 2.0;
    for (int it = 0; it < 200; ++it) {
      const double k = 0.5 * (lo + hi);
      (total(k) < target ? lo : hi) = k;
    }
    for (int32_t b = 2; b < bins; ++b) exact[b] = vertices[b] * std::min(1.0, hi * mean[b]);
  }
  std::vector<int32_t> quota(bins);
  int32_t assigned = 0;
  std::vector<std::pair<double, int32_t>> remainder;
  for (int32_t b = 0; b < bins; ++b) {
    quota[b] = int32_t(std::floor(exact[b]));
    assigned += quota[b];
    remainder.push_back({-(exact[b] - quota[b]), b});
  }
  std::sort(remainder.begin(), remainder.end());
  for (size_t i = 0; assigned < target && i < remainder.size(); ++i)
    if (quota[remainder[i].second] < vertices[remainder[i].second]) ++quota[remainder[i].second], ++assigned;
  return quota;
}

}  // namespace

bool has_zero_area(const DecimateResult& result) {
  const auto& p = result.vertices;
  for (size_t t = 0; t < result.triangles.size(); t += 3) {
    const double* a = &p[3 * size_t(result.triangles[t])];
    const double* b = &p[3 * size_t(result.triangles[t + 1])];
    const double* c = &p[3 * size_t(result.triangles[t + 2])];
    double u[3], w[3];
    for (int i = 0; i < 3; ++i) u[i] = b[i] - a[i], w[i] = c[i] - a[i];
    if (u[1] * w[2] - u[2] * w[1] == 0.0 && u[2] * w[0] - u[0] * w[2] == 0.0 && u[0] * w[1] - u[1] * w[0] == 0.0)
      return true;
  }
  return false;
}

void refine_by_collapses(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params,
                         DecimateResult& result) {
  const auto start = std::chrono::steady_clock::now();
  if (params.target_vertices < 1 && !params.zero_area_only)
    throw std::invalid_argument("refine target must be at least 1 vertex, got " +
                                std::to_string(params.target_vertices));
  const size_t n = result.kept.size();
  const auto& source = mesh.vertex_source();
  const auto& index = mesh.vertex_index();
  // Each output vertex stands for the input triangles of its cluster, and for the border
  // edges in it: planes through each border edge, perpendicular to its triangles, keep
  // collapses from pulling a border (boundary, seam, material edge) off its course.
  std::vector<Quadric> quadrics(n);
  const auto& faces = mesh.faces();
  auto label_of = [&](int32_t v) { return result.labels[source[v]]; };
  auto add_to_clusters = [&](const Quadric& q, const int32_t* vertices, int count) {
    int32_t l[3];
    for (int j = 0; j < count; ++j) {
      l[j] = label_of(vertices[j]);
      bool repeated = l[j] < 0;
      for (int i = 0; i < j; ++i) repeated = repeated || l[i] == l[j];
      if (!repeated) quadrics[l[j]].add(q);
    }
  };
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* t = &faces[3 * size_t(f)];
    Quadric plane;
    plane.add_triangle(mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]));
    add_to_clusters(plane, t, 3);
  }
  const auto& ev = mesh.edge_vertices();
  const auto& efo = mesh.edge_face_offsets();
  const auto& ef = mesh.edge_faces();
  for (int32_t e : layout.feature_edges) {
    const int32_t* ab = &ev[2 * size_t(e)];
    const double* a = mesh.position(ab[0]);
    const double* b = mesh.position(ab[1]);
    for (int32_t i = efo[e]; i < efo[e + 1]; ++i) {
      const int32_t* t = &faces[3 * size_t(ef[i])];
      int32_t opposite = t[0];
      for (int j = 0; j < 3; ++j)
        if (t[j] != ab[0] && t[j] != ab[1]) opposite = t[j];
      // A triangle standing on the edge, perpendicular to the face: its plane holds the
      // edge and the face normal; the edge length squared as its weight.
      const double* c = mesh.position(opposite);
      double u[3], w[3], n[3], top[3];
      for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], w[k] = c[k] - a[k];
      n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (len == 0) continue;
      const double edge = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (int k = 0; k < 3; ++k) top[k] = a[k] + n[k] / len * 2.0 * edge;  // area = edge^2
      Quadric plane;
      plane.add_triangle(a, b, top);
      add_to_clusters(plane, ab, 2);
    }
  }
  std::vector<double> weight(n, 1.0);
  std::vector<uint8_t> locked(n, 0);
  std::vector<int32_t> curve(n, -1), curve_size(layout.num_curves(), 0);
  auto multiplier = [&](int32_t v) { return params.multipliers ? (*params.multipliers)[v] : 1.0; };
  std::vector<int32_t> bin(n);
  for (size_t i = 0; i < n; ++i) {
    const int32_t v = index[result.kept[i]];
    const double m = multiplier(v);
    if (layout.vertex_feature[v]) curve[i] = layout.vertex_curve[v];
    if (curve[i] >= 0) ++curve_size[curve[i]];
    locked[i] = layout.vertex_corner[v] || (layout.vertex_feature[v] && curve[i] < 0) || m == kForcedMultiplier;
    if (m == kForcedMultiplier)  // a control point stays where the user put it
      for (int k = 0; k < 3; ++k) result.vertices[3 * i + k] = mesh.position(v)[k];
    weight[i] = m == kForcedMultiplier ? 1.0 : std::max(m, 1.0 / 81.0);
    bin[i] = guidance_bin(m);
  }
  // A pinched input vertex (several fans) and every vertex of its output triangles stay put:
  // the link condition sees one vertex, not the fans, and a collapse there could delete a
  // whole fan (a wing of a bowtie) while every count the final check compares stays the same.
  const auto& manifold_vertex = mesh.manifold_vertex();
  for (size_t t = 0; t < result.triangles.size() / 3; ++t) {
    bool pinched = false;
    for (int j = 0; j < 3; ++j) pinched |= !manifold_vertex[index[result.kept[result.triangles[3 * t + j]]]];
    if (pinched)
      for (int j = 0; j < 3; ++j) locked[result.triangles[3 * t + j]] = 1;
  }
  std::vector<double> bin_vertices(kBins, 0.0), bin_multipliers(kBins, 0.0);
  const auto& vfo = mesh.vertex_face_offsets();
  for (int32_t v = 0; v < mesh.num_vertices(); ++v)
    if (vfo[v] < vfo[v + 1]) {
      const int32_t b = guidance_bin(multiplier(v));
      bin_vertices[b] += 1.0;
      bin_multipliers[b] += multiplier(v);
    }
  std::vector<int32_t> quota = bin_quotas(bin_vertices, bin_multipliers, params.target_vertices);
  // Sector of every output corner at its vertex, from the input corner it copies.
  std::vector<int32_t> internal_face(mesh.report().input_triangles, -1);
  for (int32_t f = 0; f < mesh.num_faces(); ++f) internal_face[mesh.face_source()[f]] = f;
  std::vector<int32_t> corner_sector(result.corner_source.size(), 0);
  for (size_t c = 0; c < corner_sector.size(); ++c) {
    const int32_t vertex = index[result.kept[result.triangles[c]]];
    if (layout.sectors[vertex] > 1)
      corner_sector[c] = layout.sector_of(mesh, vertex, internal_face[result.corner_source[c] / 3]);
  }
  Collapser collapser(result, std::move(quadrics), std::move(weight), std::move(locked), std::move(curve),
                      std::move(curve_size), layout.curve_closed, std::move(corner_sector), std::move(bin),
                      std::move(quota));
  if (params.zero_area_only) {
    collapser.optimal_placement = false;  // the caller's positions (e.g. input vertices) stay
    result.refine_collapses += collapser.remove_zero_area();
  } else {
    result.refine_vertices = params.target_vertices;
    // Slivers the stochastic pass left (near-collinear corners) go first: the collapses thin
    // the result anyway, and none of them makes a new one (Collapser::keeps_shape).
    result.refine_collapses = collapser.remove_zero_area(kMinShape, params.target_vertices);
    result.refine_collapses += collapser.run(params.target_vertices);
    result.refine_collapses += collapser.remove_zero_area();
  }
  result.issues_remaining.sliver = collapser.zero_area_faces();
  collapser.write_back();
  result.seconds_refine = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace topstoc
