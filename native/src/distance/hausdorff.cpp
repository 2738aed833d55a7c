#include "topstoc/distance/hausdorff.hpp"
#include "distance/bounded_max.hpp"
#include "distance/vertex_stars.hpp"
#include "topstoc/core/validate.hpp"
#include "topstoc/core/parallel.hpp"
#include "../core/ordered_sum.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

namespace topstoc {

namespace {

constexpr int64_t kMaxSamples = 100000000;
// Samples handled by one task; within a task each query starts from the previous answer.
constexpr int64_t kBlock = 256;
const double kNaN = std::numeric_limits<double>::quiet_NaN();
// Loops shorter than this run serially: starting threads costs more than it saves, and far more
// when other processes hold the cores.

double length(const double* a, const double* b) {
  const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

double triangle_area(const double* a, const double* b, const double* c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// Subdivisions of a length for a step, as a double so that absurd steps cannot overflow.
double divisions(double len, double step) { return std::max(1.0, std::ceil(len / step)); }

// A number for a message: "%.6g" (std::to_string prints 1e-9 as 0.000000, and converting a
// huge count to an integer first would be undefined).
std::string shown(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", x);
  return buffer;
}

struct Lengths {
  std::vector<double> edge;     // per edge
  std::vector<double> longest;  // per triangle: longest side
};

Lengths surface_lengths(const Surface& s) {
  Lengths l;
  const auto& p = s.positions();
  const auto& e = s.edges();
  const auto& t = s.triangles();
  const int64_t num_edges = int64_t(e.size() / 2), m = s.num_triangles();
  l.edge.resize(num_edges);
  l.longest.resize(m);
  parallel_for(0, num_edges, kParallelMin, [&](int64_t i) { l.edge[i] = length(&p[3 * size_t(e[2 * i])], &p[3 * size_t(e[2 * i + 1])]); });
  parallel_for(0, m, kParallelMin, [&](int64_t f) {
    const double* a = &p[3 * size_t(t[3 * f])];
    const double* b = &p[3 * size_t(t[3 * f + 1])];
    const double* c = &p[3 * size_t(t[3 * f + 2])];
    l.longest[f] = std::max({length(a, b), length(b, c), length(c, a)});
  });
  return l;
}

int64_t used_vertex_count(const Surface& s) {
  int64_t n = 0;
  for (auto u : s.used()) n += u;
  return n;
}

// Samples sample_surface would make for `step` (as a double: it may be huge).
// Summed in fixed blocks (ordered_sum.hpp): the terms are whole numbers, exact in any order below
// 2^53, but an absurd step's count (reported in the error message) would otherwise round
// differently on different thread counts.
double sample_count(const Lengths& l, int64_t vertices, double step) {
  const double edge_samples =
      ordered_sum(int64_t(l.edge.size()), [&](int64_t i) { return divisions(l.edge[i], step) - 1.0; });
  const double face_samples = ordered_sum(int64_t(l.longest.size()), [&](int64_t f) {
    const double n = divisions(l.longest[f], step);
    return n * n;
  });
  return double(vertices) + edge_samples + face_samples;
}


}  // namespace

// --- Surface ---------------------------------------------------------------------------------

Surface::Surface(std::vector<double> positions, std::vector<int32_t> triangles)
    : positions_(std::move(positions)), triangles_(std::move(triangles)) {
  if (positions_.size() % 3 != 0) throw std::invalid_argument("positions must hold 3 coordinates per vertex");
  if (triangles_.size() % 3 != 0) throw std::invalid_argument("triangles must hold 3 vertex ids each");
  if (positions_.empty()) throw std::invalid_argument("mesh has no vertices");
  if (triangles_.empty()) throw std::invalid_argument("mesh has no triangles");
  if (positions_.size() / 3 > size_t(INT32_MAX) || triangles_.size() / 3 > size_t(INT32_MAX / 3))
    throw std::invalid_argument("mesh is too large for 32-bit indices");
  const int32_t n = num_vertices(), m = num_triangles();
  require_finite_positions(positions_.data(), n);
  require_indices_in_range(triangles_.data(), m, 3, n, "triangle");
  used_.assign(n, 0);
  for (int32_t v : triangles_) used_[v] = 1;

  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (int32_t v = 0; v < n; ++v)
    if (used_[v])
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], positions_[3 * size_t(v) + k]);
        hi[k] = std::max(hi[k], positions_[3 * size_t(v) + k]);
      }
  diagonal_ = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
  double area = 0.0;
  for (int32_t f = 0; f < m; ++f) {
    const int32_t* t = &triangles_[3 * size_t(f)];
    area += triangle_area(&positions_[3 * size_t(t[0])], &positions_[3 * size_t(t[1])], &positions_[3 * size_t(t[2])]);
  }
  area_ = area;
}

void Surface::build_edges() const {
  // Distinct edges, built on first use (sampling needs them, closest-point queries do not): sort
  // the (low, high, side) keys of all triangle sides.
  const int32_t m = num_triangles();
  std::vector<std::pair<uint64_t, int64_t>> sides;
  sides.reserve(3 * size_t(m));
  face_edges_.assign(3 * size_t(m), -1);
  for (int64_t s = 0; s < 3 * int64_t(m); ++s) {
    const int32_t a = triangles_[s], b = triangles_[s - s % 3 + (s % 3 + 1) % 3];
    if (a == b) continue;
    const uint64_t key = (uint64_t(uint32_t(std::min(a, b))) << 32) | uint32_t(std::max(a, b));
    sides.emplace_back(key, s);
  }
  std::sort(sides.begin(), sides.end());
  for (size_t i = 0; i < sides.size(); ++i) {
    if (i == 0 || sides[i].first != sides[i - 1].first) {
      edges_.push_back(int32_t(sides[i].first >> 32));
      edges_.push_back(int32_t(sides[i].first & 0xffffffffu));
    }
    face_edges_[sides[i].second] = int32_t(edges_.size() / 2 - 1);
  }
}

const std::vector<int32_t>& Surface::edges() const {
  std::call_once(edges_once_, [this] { build_edges(); });
  return edges_;
}

const std::vector<int32_t>& Surface::face_edges() const {
  std::call_once(edges_once_, [this] { build_edges(); });
  return face_edges_;
}

const TriangleBvh& Surface::bvh() const {
  std::call_once(bvh_once_, [this] {
    bvh_ = std::make_unique<TriangleBvh>(positions_.data(), triangles_.data(), int64_t(num_triangles()));
  });
  return *bvh_;
}

// --- sampling ----------------------------------------------------------------------------------

SurfaceSamples sample_surface(const Surface& surface, double step) {
  if (!(step > 0.0) || !std::isfinite(step))
    throw std::invalid_argument("sample step must be a positive number, got " + shown(step));
  const Lengths lengths = surface_lengths(surface);
  const int64_t vertices = used_vertex_count(surface);
  const double wanted = sample_count(lengths, vertices, step);
  if (wanted > double(kMaxSamples))
    throw std::invalid_argument("sample step " + shown(step) + " would need " + shown(wanted) +
                                " samples (more than " + std::to_string(kMaxSamples) + "): use a larger step");

  const auto& p = surface.positions();
  const auto& t = surface.triangles();
  const auto& e = surface.edges();
  const int64_t num_edges = int64_t(e.size() / 2), m = surface.num_triangles();
  SurfaceSamples s;
  s.step = step;

  // Offsets: vertices, then edges, then faces.
  std::vector<int64_t> edge_offsets(num_edges + 1);
  s.face_offsets.resize(m + 1);
  s.face_weight.resize(m);
  int64_t total = vertices;
  for (int64_t i = 0; i < num_edges; ++i) {
    edge_offsets[i] = total;
    total += int64_t(divisions(lengths.edge[i], step)) - 1;
  }
  edge_offsets[num_edges] = total;
  for (int64_t f = 0; f < m; ++f) {
    s.face_offsets[f] = total;
    const int64_t n = int64_t(divisions(lengths.longest[f], step));
    total += n * n;
  }
  s.face_offsets[m] = total;
  s.num_vertex_samples = vertices;
  s.num_edge_samples = edge_offsets[num_edges] - vertices;
  s.num_face_samples = total - edge_offsets[num_edges];
  s.points.resize(3 * size_t(total));
  s.element.resize(total);

  int64_t next = 0;
  for (int32_t v = 0; v < surface.num_vertices(); ++v)
    if (surface.used()[v]) {
      std::copy_n(&p[3 * size_t(v)], 3, &s.points[3 * size_t(next)]);
      s.element[next++] = v;
    }
  parallel_for(0, num_edges, kParallelMin, [&](int64_t i) {
    const double* a = &p[3 * size_t(e[2 * i])];
    const double* b = &p[3 * size_t(e[2 * i + 1])];
    const int64_t n = edge_offsets[i + 1] - edge_offsets[i] + 1;
    for (int64_t k = 1; k < n; ++k) {
      const int64_t out = edge_offsets[i] + k - 1;
      const double x = double(k) / double(n);
      for (int c = 0; c < 3; ++c) s.points[3 * size_t(out) + c] = a[c] + x * (b[c] - a[c]);
      s.element[out] = int32_t(i);
    }
  });
  parallel_for_dynamic(0, m, 1024, parallel_if(total >= kParallelMin), [&](int64_t f) {
    const double* a = &p[3 * size_t(t[3 * f])];
    const double* b = &p[3 * size_t(t[3 * f + 1])];
    const double* c = &p[3 * size_t(t[3 * f + 2])];
    const int64_t n = int64_t(divisions(lengths.longest[f], step));
    s.face_weight[f] = triangle_area(a, b, c) / double(n * n);
    int64_t out = s.face_offsets[f];
    auto emit = [&](double u, double v) {  // barycentric (1 - u - v, u, v)
      for (int k = 0; k < 3; ++k) s.points[3 * size_t(out) + k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
      s.element[out++] = int32_t(f);
    };
    // Centroids of the n^2 similar sub-triangles: "upward" ones at (i + 1/3, j + 1/3) / n,
    // "downward" ones at (i + 2/3, j + 2/3) / n.
    const double inv = 1.0 / double(n);
    for (int64_t i = 0; i < n; ++i)
      for (int64_t j = 0; i + j < n; ++j) {
        emit((double(i) + 1.0 / 3.0) * inv, (double(j) + 1.0 / 3.0) * inv);
        if (i + j + 2 <= n) emit((double(i) + 2.0 / 3.0) * inv, (double(j) + 2.0 / 3.0) * inv);
      }
  });
  return s;
}

double step_for_sample_count(const Surface& surface, int64_t samples) {
  if (samples <= 0) throw std::invalid_argument("sample count must be positive, got " + std::to_string(samples));
  if (samples > kMaxSamples)
    throw std::invalid_argument("sample count " + std::to_string(samples) + " exceeds the limit of " +
                                std::to_string(kMaxSamples));
  const Lengths lengths = surface_lengths(surface);
  const int64_t vertices = used_vertex_count(surface);
  double coarse = 0.0;
  for (double x : lengths.longest) coarse = std::max(coarse, x);
  if (!(coarse > 0.0)) return 1.0;  // every triangle is a point: any step gives one sample each
  // Halve until there are more samples than wanted, then bisect (the count falls as the step grows).
  double hi = coarse, lo = coarse;
  if (sample_count(lengths, vertices, hi) >= double(samples)) return hi;
  for (int i = 0; i < 60 && sample_count(lengths, vertices, lo) <= double(samples); ++i) lo *= 0.5;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (sample_count(lengths, vertices, mid) <= double(samples) ? hi : lo) = mid;
  }
  return hi;
}

// --- distances ---------------------------------------------------------------------------------

std::vector<ClosestHit> closest_points(const Surface& surface, const double* points, int64_t count,
                                       double within) {
  const TriangleBvh& bvh = surface.bvh();
  const double within2 = within >= 0.0 ? within * within : -1.0;
  std::vector<ClosestHit> hits(count);
  const int64_t blocks = (count + kBlock - 1) / kBlock;
  parallel_for_dynamic(0, blocks, 4, parallel_if(count >= 4 * kBlock), [&](int64_t block) {
    int32_t hint = -1;
    for (int64_t i = block * kBlock; i < std::min(count, (block + 1) * kBlock); ++i) {
      hits[i] = bvh.closest(points + 3 * i, hint, within2);
      hint = hits[i].slot;
    }
  });
  return hits;
}

OneSidedDistance one_sided_distance(const Surface& from, const SurfaceSamples& samples, const Surface& to,
                                    double percentile_fraction) {
  if (percentile_fraction > 1.0 || std::isnan(percentile_fraction))
    throw std::invalid_argument("percentile must be a fraction in (0, 1], got " + std::to_string(percentile_fraction));
  const int64_t count = samples.size();
  const int64_t m = from.num_triangles();
  if (int64_t(samples.face_offsets.size()) != m + 1)
    throw std::invalid_argument("samples were not taken on this surface");

  // Distances of every sample, in parallel; each block of samples chains its hints.
  std::vector<double> distance(count);
  {
    const TriangleBvh& bvh = to.bvh();
    const int64_t blocks = (count + kBlock - 1) / kBlock;
    parallel_for_dynamic(0, blocks, 4, parallel_if(count >= 4 * kBlock), [&](int64_t block) {
      int32_t hint = -1;
      for (int64_t i = block * kBlock; i < std::min(count, (block + 1) * kBlock); ++i) {
        const ClosestHit hit = bvh.closest(&samples.points[3 * size_t(i)], hint);
        distance[i] = std::sqrt(hit.distance2);
        hint = hit.slot;
      }
    });
  }

  OneSidedDistance r;
  r.samples = count;
  // Maximum: first sample holding the largest value (serial, so the same with any thread count).
  int64_t arg = 0;
  for (int64_t i = 1; i < count; ++i)
    if (distance[i] > distance[arg]) arg = i;
  r.max = count ? distance[arg] : 0.0;
  if (count) std::copy_n(&samples.points[3 * size_t(arg)], 3, r.max_point);

  // Area-weighted mean and RMS over the face samples, summed in a fixed order. Weights are
  // taken relative to the largest and distances relative to the max: with coordinates of 1e150
  // an area times a distance overflows (NaN means before).
  double largest_weight = 0.0;
  for (int64_t f = 0; f < m; ++f)
    if (std::isfinite(samples.face_weight[f])) largest_weight = std::max(largest_weight, samples.face_weight[f]);
  const double unit = r.max > 0.0 && std::isfinite(r.max) ? r.max : 1.0;
  double area = 0.0, sum = 0.0, sum2 = 0.0;
  for (int64_t f = 0; f < m && largest_weight > 0.0; ++f) {
    double face_sum = 0.0, face_sum2 = 0.0;
    for (int64_t i = samples.face_offsets[f]; i < samples.face_offsets[f + 1]; ++i) {
      const double x = distance[i] / unit;
      face_sum += x;
      face_sum2 += x * x;
    }
    const double w = samples.face_weight[f] / largest_weight;
    area += w * double(samples.face_offsets[f + 1] - samples.face_offsets[f]);
    sum += w * face_sum;
    sum2 += w * face_sum2;
  }
  if (area > 0.0) {
    r.mean = unit * (sum / area);
    r.rms = unit * std::sqrt(sum2 / area);
  } else {  // a surface without area: plain average over all samples
    sum = sum2 = 0.0;
    for (int64_t i = 0; i < count; ++i) {
      sum += distance[i] / unit;
      sum2 += (distance[i] / unit) * (distance[i] / unit);
    }
    r.mean = count ? unit * (sum / double(count)) : 0.0;
    r.rms = count ? unit * std::sqrt(sum2 / double(count)) : 0.0;
  }

  // Percentile: the smallest distance d with at least the asked fraction of the area within d.
  r.percentile = kNaN;
  if (percentile_fraction > 0.0) {
    const int64_t first_face = samples.face_offsets[0];
    std::vector<std::pair<double, double>> ranked;  // (distance, weight)
    ranked.reserve(count - first_face);
    for (int64_t f = 0; f < m; ++f)
      for (int64_t i = samples.face_offsets[f]; i < samples.face_offsets[f + 1]; ++i)
        ranked.emplace_back(distance[i], area > 0.0 ? samples.face_weight[f] / largest_weight : 1.0);
    std::sort(ranked.begin(), ranked.end());
    double total = 0.0;
    for (const auto& x : ranked) total += x.second;
    double running = 0.0;
    for (const auto& x : ranked) {
      running += x.second;
      r.percentile = x.first;
      if (running >= percentile_fraction * total) break;
    }
  }

  // Per-element errors of the sampled surface.
  const auto& t = from.triangles();
  const auto& fe = from.face_edges();
  r.vertex_distance.assign(from.num_vertices(), kNaN);
  for (int64_t i = 0; i < samples.num_vertex_samples; ++i) r.vertex_distance[samples.element[i]] = distance[i];
  std::vector<double> edge_max(from.edges().size() / 2, 0.0);
  for (int64_t i = samples.num_vertex_samples; i < samples.num_vertex_samples + samples.num_edge_samples; ++i)
    edge_max[samples.element[i]] = std::max(edge_max[samples.element[i]], distance[i]);
  r.face_max.assign(m, 0.0);
  parallel_for(0, m, kParallelMin, [&](int64_t f) {
    double x = 0.0;
    for (int64_t i = samples.face_offsets[f]; i < samples.face_offsets[f + 1]; ++i) x = std::max(x, distance[i]);
    for (int c = 0; c < 3; ++c) {
      x = std::max(x, r.vertex_distance[t[3 * f + c]]);
      if (fe[3 * f + c] >= 0) x = std::max(x, edge_max[fe[3 * f + c]]);
    }
    r.face_max[f] = x;
  });
  return r;
}

// Replaces the sampled max (a lower bound) by a bracket within the tolerance (bounded_max.hpp).
void bracket_max(const Surface& from, const Surface& to, OneSidedDistance& side, double tolerance) {
  if (!(tolerance > 0.0)) return;
  const MaxBracket bracket = bound_max_distance(from, side.vertex_distance, to, side.max, side.max_point, tolerance);
  side.max = bracket.lower;
  std::copy_n(bracket.lower_point, 3, side.max_point);
  side.max_upper = bracket.upper;
  // Per-triangle errors stay consistent with the max (face_max.max() == max).
  if (bracket.lower_triangle >= 0)
    side.face_max[bracket.lower_triangle] = std::max(side.face_max[bracket.lower_triangle], bracket.lower);
  side.refine_queries = bracket.queries;
}

namespace {

OneSidedBracket one_sided(const MaxBracket& bracket) {
  OneSidedBracket r;
  r.lower = bracket.lower;
  r.upper = bracket.upper;
  std::copy_n(bracket.lower_point, 3, r.lower_point);
  r.queries = bracket.queries;
  r.converged = bracket.converged;
  return r;
}

}  // namespace

OneSidedBracket bracket_one_sided_max(const Surface& from, const Surface& to, double tolerance, int64_t max_queries,
                                      double threshold) {
  if (!(tolerance > 0.0)) throw std::invalid_argument("tolerance must be positive, got " + shown(tolerance));
  return one_sided(bound_max_distance_by_tree(from, to, tolerance, max_queries, threshold, true));
}

SymmetricBracket bracket_symmetric_max(const Surface& a, const Surface& b, double tolerance, double resolution,
                                       int64_t max_queries) {
  if (!(tolerance > 0.0)) throw std::invalid_argument("tolerance must be positive, got " + shown(tolerance));
  if (!(resolution >= 0.0)) throw std::invalid_argument("resolution must not be negative, got " + shown(resolution));
  a.bvh(), b.bvh();  // built before the sides share them, as are the triangles around each vertex
  std::unique_ptr<const Stars> a_stars, b_stars;
  parallel_invoke(true, [&] { a_stars = std::make_unique<const Stars>(a); },
                  [&] { b_stars = std::make_unique<const Stars>(b); });
  SymmetricBracket r;
  parallel_invoke(
      true,
      [&] {
        r.forward = one_sided(bound_max_from_vertices(a, b, tolerance, resolution, max_queries, *a_stars, *b_stars));
      },
      [&] {
        r.backward = one_sided(bound_max_from_vertices(b, a, tolerance, resolution, max_queries, *b_stars, *a_stars));
      });
  return r;
}

HausdorffResult hausdorff(const Surface& a, const SurfaceSamples& a_samples, const Surface& b, double percentile,
                          double max_tolerance) {
  HausdorffResult r;
  r.step = a_samples.step;
  r.diagonal = a.diagonal();
  r.forward = one_sided_distance(a, a_samples, b, percentile);
  r.backward = one_sided_distance(b, sample_surface(b, a_samples.step), a, percentile);
  bracket_max(a, b, r.forward, max_tolerance);
  bracket_max(b, a, r.backward, max_tolerance);
  r.symmetric_max_upper = std::max(r.forward.max_upper, r.backward.max_upper);
  r.symmetric_max = std::max(r.forward.max, r.backward.max);
  r.symmetric_mean = std::max(r.forward.mean, r.backward.mean);
  r.symmetric_rms = std::max(r.forward.rms, r.backward.rms);
  r.symmetric_percentile = percentile > 0.0 ? std::max(r.forward.percentile, r.backward.percentile) : kNaN;
  return r;
}

HausdorffResult hausdorff(const Surface& a, const Surface& b, const HausdorffParams& params) {
  if (params.step < 0.0 || std::isnan(params.step))
    throw std::invalid_argument("sample step must not be negative, got " + std::to_string(params.step));
  const double step = params.step > 0.0 ? params.step : step_for_sample_count(a, params.samples);
  return hausdorff(a, sample_surface(a, step), b, params.percentile, params.max_tolerance);
}

}  // namespace topstoc
