#include "edit/patch_fairing.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/portable.hpp"
#include "topstoc/core/quality.hpp"

namespace topstoc {

namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec& a) { return std::sqrt(dot(a, a)); }

uint64_t pair_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

Vec position(const PatchMesh& patch, int32_t v) {
  const int32_t k = static_cast<int32_t>(patch.boundary.size() / 3);
  const double* p = v < k ? &patch.boundary[3 * size_t(v)] : &patch.added[3 * size_t(v - k)];
  return {p[0], p[1], p[2]};
}

double angle_at(const Vec& apex, const Vec& a, const Vec& b) {
  const Vec u = sub(a, apex), w = sub(b, apex);
  return std::atan2(norm(cross(u, w)), dot(u, w));
}

// Edge -> the (one or two) patch triangles holding it.
std::unordered_map<uint64_t, std::array<int32_t, 2>> edge_triangles(const PatchMesh& patch) {
  std::unordered_map<uint64_t, std::array<int32_t, 2>> edges;
  edges.reserve(2 * patch.triangles.size());
  for (int32_t t = 0; t < int32_t(patch.triangles.size()); ++t)
    for (int c = 0; c < 3; ++c) {
      auto& h = edges.try_emplace(pair_key(patch.triangles[t][c], patch.triangles[t][(c + 1) % 3]),
                                  std::array<int32_t, 2>{-1, -1})
                    .first->second;
      h[h[0] < 0 ? 0 : 1] = t;
    }
  return edges;
}

// Flips interior patch edges whose opposite angles sum to more than pi (not Delaunay), in
// passes, while the flip keeps both triangles non-degenerate and facing the same way.
void relax(PatchMesh& patch, const ForbiddenDiagonal& forbidden) {
  const int32_t k = static_cast<int32_t>(patch.boundary.size() / 3);
  for (int pass = 0; pass < 50; ++pass) {
    auto edges = edge_triangles(patch);
    std::vector<uint64_t> keys;
    keys.reserve(edges.size());
    for (const auto& e : edges)
      if (e.second[1] >= 0) keys.push_back(e.first);
    std::sort(keys.begin(), keys.end());  // deterministic
    std::vector<uint8_t> touched(patch.triangles.size(), 0);
    bool flipped = false;
    for (uint64_t key : keys) {
      const auto holders = edges[key];
      const int32_t t1 = holders[0], t2 = holders[1];
      if (touched[t1] || touched[t2]) continue;  // changed this pass: look again next pass
      int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu);
      auto& x = patch.triangles[t1];
      int c0 = 0;
      while (x[c0] != a) ++c0;
      if (x[(c0 + 1) % 3] != b) std::swap(a, b);  // now t1 runs a -> b
      auto third = [&](const std::array<int32_t, 3>& t) {
        for (int32_t v : t)
          if (v != a && v != b) return v;
        return -1;
      };
      const int32_t c = third(patch.triangles[t1]), d = third(patch.triangles[t2]);
      if (c == d || edges.count(pair_key(c, d))) continue;
      if (c < k && d < k && forbidden && forbidden(c, d)) continue;
      const Vec pa = position(patch, a), pb = position(patch, b), pc = position(patch, c), pd = position(patch, d);
      if (angle_at(pc, pa, pb) + angle_at(pd, pa, pb) <= kPi + 1e-9) continue;
      const Vec n_old = cross(sub(pb, pa), sub(pc, pa));
      const Vec n_old2 = cross(sub(pa, pb), sub(pd, pb));
      const Vec n1 = cross(sub(pd, pa), sub(pc, pa)), n2 = cross(sub(pb, pd), sub(pc, pd));
      const Vec mean{n_old[0] + n_old2[0], n_old[1] + n_old2[1], n_old[2] + n_old2[2]};
      const double scale = dot(sub(pc, pd), sub(pc, pd)) * 1e-12;
      if (dot(n1, mean) <= 0 || dot(n2, mean) <= 0 || norm(n1) <= scale || norm(n2) <= scale) continue;
      patch.triangles[t1] = {a, d, c};
      patch.triangles[t2] = {d, b, c};
      touched[t1] = touched[t2] = 1;
      flipped = true;
    }
    if (!flipped) break;
  }
}

}  // namespace

void refine_patch(PatchMesh& patch, const PatchRing& ring, const ForbiddenDiagonal& forbidden) {
  const int32_t k = static_cast<int32_t>(patch.boundary.size() / 3);
  // Target edge length at each vertex: the mean length of the surface's edges at a boundary
  // corner; an added vertex inherits the mean of the triangle it split.
  std::vector<double> sigma(k);
  for (int32_t i = 0; i < k; ++i) {
    const Vec p = position(patch, i);
    double sum = norm(sub(position(patch, (i + 1) % k), p)) + norm(sub(position(patch, (i + k - 1) % k), p));
    for (const auto& q : ring.outer[i]) sum += norm(sub(q, p));
    sigma[i] = sum / double(2 + ring.outer[i].size());
  }
  double mean_sigma = 0;
  for (double s : sigma) mean_sigma += s / k;
  sigma.resize(k + patch.added.size() / 3, mean_sigma);
  const size_t limit = 50 * size_t(k);
  relax(patch, forbidden);
  const double alpha = std::sqrt(2.0);
  for (int round = 0; round < 200; ++round) {
    bool split = false;
    const size_t count = patch.triangles.size();
    for (size_t t = 0; t < count && patch.added.size() / 3 < limit; ++t) {
      const auto tri = patch.triangles[t];
      const Vec a = position(patch, tri[0]), b = position(patch, tri[1]), c = position(patch, tri[2]);
      const Vec centre{(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
      const double s = (sigma[tri[0]] + sigma[tri[1]] + sigma[tri[2]]) / 3;
      bool coarse = true;
      for (int m = 0; m < 3 && coarse; ++m) {
        const double d = alpha * norm(sub(centre, position(patch, tri[m])));
        coarse = d > s && d > sigma[tri[m]];
      }
      if (!coarse) continue;
      const int32_t id = k + static_cast<int32_t>(patch.added.size() / 3);
      patch.added.insert(patch.added.end(), centre.begin(), centre.end());
      sigma.push_back(s);
      patch.triangles[t] = {tri[0], tri[1], id};
      patch.triangles.push_back({tri[1], tri[2], id});
      patch.triangles.push_back({tri[2], tri[0], id});
      split = true;
    }
    if (!split) break;
    relax(patch, forbidden);
  }
}

void fair_patch(PatchMesh& patch, const PatchRing& ring) {
  const int32_t k = static_cast<int32_t>(patch.boundary.size() / 3);
  const int32_t free_count = static_cast<int32_t>(patch.added.size() / 3);
  if (free_count == 0) return;
  const int32_t n = k + free_count;
  std::vector<std::vector<int32_t>> neighbours(n);
  for (const auto& t : patch.triangles)
    for (int c = 0; c < 3; ++c) {
      neighbours[t[c]].push_back(t[(c + 1) % 3]);
      neighbours[t[c]].push_back(t[(c + 2) % 3]);
    }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  // Umbrella operator L(v) = mean of v's neighbours - v, rows over every patch vertex; the
  // boundary corners' rows also see the fixed ring. Split into A x + b, x = added positions.
  std::vector<double> inverse_degree(n);
  for (int32_t v = 0; v < n; ++v) {
    const size_t degree = neighbours[v].size() + (v < k ? ring.outer[v].size() : 0);
    inverse_degree[v] = degree ? 1.0 / double(degree) : 0.0;
  }
  auto apply = [&](const std::vector<double>& x, std::vector<double>& y) {  // y = A x (one coordinate)
    y.assign(n, 0.0);
    for (int32_t v = 0; v < n; ++v) {
      double sum = 0;
      for (int32_t w : neighbours[v])
        if (w >= k) sum += x[w - k];
      y[v] = sum * inverse_degree[v] - (v >= k ? x[v - k] : 0.0);
    }
  };
  auto apply_transposed = [&](const std::vector<double>& y, std::vector<double>& x) {
    x.assign(free_count, 0.0);
    for (int32_t v = 0; v < n; ++v) {
      for (int32_t w : neighbours[v])
        if (w >= k) x[w - k] += y[v] * inverse_degree[v];
      if (v >= k) x[v - k] -= y[v];
    }
  };
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> b(n, 0.0), x(free_count), rhs, r, p, ap, atap;
    for (int32_t v = 0; v < n; ++v) {
      double sum = 0;
      for (int32_t w : neighbours[v])
        if (w < k) sum += patch.boundary[3 * size_t(w) + axis];
      if (v < k)
        for (const auto& q : ring.outer[v]) sum += q[axis];
      b[v] = sum * inverse_degree[v] - (v < k ? patch.boundary[3 * size_t(v) + axis] : 0.0);
    }
    for (int32_t j = 0; j < free_count; ++j) x[j] = patch.added[3 * size_t(j) + axis];
    // Conjugate gradients on A^T A x = -A^T b.
    apply_transposed(b, rhs);
    for (double& value : rhs) value = -value;
    apply(x, ap);
    apply_transposed(ap, atap);
    r.resize(free_count);
    for (int32_t j = 0; j < free_count; ++j) r[j] = rhs[j] - atap[j];
    p = r;
    double rr = 0, rhs_norm = 0;
    for (int32_t j = 0; j < free_count; ++j) rr += r[j] * r[j], rhs_norm += rhs[j] * rhs[j];
    const double tolerance = 1e-24 * std::max(rhs_norm, 1e-300);
    for (int32_t iteration = 0; iteration < 20 * free_count + 200 && rr > tolerance; ++iteration) {
      apply(p, ap);
      apply_transposed(ap, atap);
      double pap = 0;
      for (int32_t j = 0; j < free_count; ++j) pap += p[j] * atap[j];
      if (!(pap > 0)) break;
      const double step = rr / pap;
      double next_rr = 0;
      for (int32_t j = 0; j < free_count; ++j) {
        x[j] += step * p[j];
        r[j] -= step * atap[j];
        next_rr += r[j] * r[j];
      }
      for (int32_t j = 0; j < free_count; ++j) p[j] = r[j] + (next_rr / rr) * p[j];
      rr = next_rr;
    }
    for (int32_t j = 0; j < free_count; ++j) patch.added[3 * size_t(j) + axis] = x[j];
  }
}

namespace {

double aspect(const Vec& a, const Vec& b, const Vec& c) { return aspect_ratio(a.data(), b.data(), c.data()); }

// Lifting the centroid g of triangle abc to g + h n (n its unit normal) and joining it to the
// corners: the worst aspect of the three triangles.
struct Lift {
  Vec a, b, c, centre, normal;
  double worst(double h) const {
    const Vec p{centre[0] + h * normal[0], centre[1] + h * normal[1], centre[2] + h * normal[2]};
    return std::max({aspect(a, b, p), aspect(b, c, p), aspect(c, a, p)});
  }
  // The height with the least worst aspect: sampled up to twice the longest side (the worst
  // aspect only grows beyond), then refined around the best sample.
  double best_height() const {
    double step = 2 * std::max({norm(sub(a, b)), norm(sub(b, c)), norm(sub(c, a))}) / 64, best_h = 0;
    double best = worst(0);
    for (int i = 1; i <= 64; ++i)
      if (const double w = worst(i * step); w < best) best = w, best_h = i * step;
    for (int round = 0; round < 20; ++round) {
      step *= 0.5;
      for (double h : {best_h - step, best_h + step})
        if (const double w = worst(h); h > 0 && w < best) best = w, best_h = h;
    }
    return best_h;
  }
  // The height nearest `wanted` (never above the best height: higher only bulges more and
  // shapes worse) whose worst aspect is within max_aspect, by bisection towards the best
  // height; the best height when none is. A small margin keeps a recomputation within too.
  double height_near(double wanted, double max_aspect) const {
    const double best_h = best_height(), limit = max_aspect * (1 - 1e-9);
    double good = best_h, bad = std::min(wanted, best_h);
    if (worst(bad) <= limit || !(worst(good) <= limit)) return worst(bad) <= limit ? bad : good;
    for (int round = 0; round < 40; ++round) {
      const double middle = 0.5 * (good + bad);
      (worst(middle) <= limit ? good : bad) = middle;
    }
    return good;
  }
};

}  // namespace

void lift_slivers(PatchMesh& patch, const PatchRing& ring, double max_aspect) {
  const int32_t k = static_cast<int32_t>(patch.boundary.size() / 3);
  std::vector<Lift> lifts;
  const size_t first = patch.added.size(), count = patch.triangles.size();
  for (size_t t = 0; t < count; ++t) {
    const auto tri = patch.triangles[t];
    const Vec a = position(patch, tri[0]), b = position(patch, tri[1]), c = position(patch, tri[2]);
    const Vec normal = cross(sub(b, a), sub(c, a));
    const double own = aspect(a, b, c), length = norm(normal);
    if (!(own > max_aspect) || !(length > 0)) continue;
    const Vec g{(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
    const Lift lift{a, b, c, g, {normal[0] / length, normal[1] / length, normal[2] / length}};
    if (!(lift.worst(lift.best_height()) < own)) continue;  // a needle too thin for one vertex: left as is
    const int32_t id = k + static_cast<int32_t>(patch.added.size() / 3);
    patch.added.insert(patch.added.end(), g.begin(), g.end());
    patch.triangles[t] = {tri[0], tri[1], id};
    patch.triangles.push_back({tri[1], tri[2], id});
    patch.triangles.push_back({tri[2], tri[0], id});
    lifts.push_back(lift);
  }
  if (lifts.empty()) return;
  // Each new vertex goes where the fairing puts it above or below its triangle (the surface's
  // continuation), or as near there as keeps its triangles within max_aspect. The others stay.
  PatchMesh faired = patch;
  fair_patch(faired, ring);
  for (size_t j = 0; j < lifts.size(); ++j) {
    const Lift& lift = lifts[j];
    double rise = 0;
    for (int i = 0; i < 3; ++i) rise += (faired.added[first + 3 * j + i] - lift.centre[i]) * lift.normal[i];
    const double height = std::copysign(lift.height_near(std::abs(rise), max_aspect), rise);
    for (int i = 0; i < 3; ++i) patch.added[first + 3 * j + i] = lift.centre[i] + height * lift.normal[i];
  }
}

}  // namespace topstoc
