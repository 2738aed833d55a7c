#include "topstoc/decimate/sampling.hpp"
#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <cstring>
#include <stdexcept>
#include <string>

#include <limits>
#include <memory>

#include "core/counting_sort.hpp"
#include "core/id_bits.hpp"
#include "core/ordered_sum.hpp"
#include "core/portable.hpp"
#include "core/sort_by_value.hpp"
#include "decimate/candidate_order.hpp"
#include "decimate/draw.hpp"
#include "topstoc/core/random.hpp"

namespace topstoc {

using namespace draw;  // the classes, tables and key test shared with candidate_order.cpp

namespace {

std::vector<uint8_t> classify(const Mesh& mesh, const FeatureLayout& layout) {
  const int32_t n = mesh.num_vertices();
  std::vector<uint8_t> cls(n);
  for (int32_t v = 0; v < n; ++v)
    cls[v] = !mesh.in_faces(v) ? kIsolated
             : layout.is_corner(v) ? kCorner
             : layout.is_feature_vertex(v) ? kCurve
                                        : kSurface;
  return cls;
}

bool inside_box(const BoxGuidance& box, const double* p) {
  const double* m = box.world_to_box;
  for (int r = 0; r < 3; ++r) {
    const double c = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
    if (std::abs(c) > 1.0) return false;
  }
  return true;
}

bool inside_frustum(const ViewGuidance& view, const double* p) {
  const double* m = view.view_projection;
  double clip[4];
  for (int r = 0; r < 4; ++r) clip[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
  if (clip[3] <= 0) return false;
  for (int r = 0; r < 3; ++r)
    if (std::abs(clip[r]) > clip[3]) return false;
  return true;
}

// Silhouette band, back faces and frustum (thesis 4.4) applied to p for one vertex.
double apply_view(const ViewGuidance& view, const double* position, const double* normal, double p) {
  double to_eye[3];
  if (view.perspective) {
    for (int k = 0; k < 3; ++k) to_eye[k] = view.eye[k] - position[k];
  } else {
    for (int k = 0; k < 3; ++k) to_eye[k] = -view.direction[k];
  }
  const double len = std::sqrt(to_eye[0] * to_eye[0] + to_eye[1] * to_eye[1] + to_eye[2] * to_eye[2]);
  const double facing = len > 0 ? (normal[0] * to_eye[0] + normal[1] * to_eye[1] + normal[2] * to_eye[2]) / len : 1.0;
  const double band = (1.0 - std::cos(view.silhouette_angle)) / 2.0;
  const double away = std::abs(facing);
  if (facing < 0) p *= view.back_ratio;
  if (away <= band) {
    p = 1.0;
  } else if (view.silhouette_falloff > 0 && away < band + view.silhouette_falloff) {
    const double t = (away - band) / view.silhouette_falloff;  // 0 at the band, 1 outside
    p = (1.0 - t) * 1.0 + t * p;
  }
  if (view.frustum && !inside_frustum(view, position)) p = std::min(p, view.outside_probability);
  return p;
}

}  // namespace

Importance draw::importance(const Mesh& mesh, const ImportanceTable& table) {
  // The vertex areas are built on first use: asked for here, before any loop reads them.
  const double mean_area = table.area_weighted ? mesh.mean_vertex_area() : 0.0;
  const double* area = mean_area > 0 ? mesh.vertex_areas().data() : nullptr;
  return Importance(table, mesh.weights().data(), mesh.mean_weight(), area, mean_area);
}

namespace {

std::shared_ptr<const ImportanceTable> importance_table(const Mesh& mesh, const FeatureLayout& layout,
                                                        const SamplingParams& params) {
  auto cached = std::static_pointer_cast<const ImportanceTable>(layout.sampling_table.get());
  if (cached && cached->adaptivity == params.adaptivity && cached->flat_floor == params.flat_floor &&
      cached->area_weighted == params.area_weighted && int32_t(cached->cls.size()) == mesh.num_vertices())
    return cached;
  auto table = std::make_shared<ImportanceTable>();
  table->adaptivity = params.adaptivity;
  table->flat_floor = params.flat_floor;
  table->area_weighted = params.area_weighted;
  table->cls = classify(mesh, layout);
  const auto& cls = table->cls;
  const int32_t n = mesh.num_vertices();
  const Importance q = importance(mesh, *table);
  table->surface.ids.reserve(n);
  for (int32_t v = 0; v < n; ++v) {
    const double qv = q(v);
    if (cls[v] == kSurface) table->surface.ids.push_back(v);
    else if (cls[v] == kCurve) table->curve.ids.push_back(v);
    else if (cls[v] == kCorner) table->corners += 1.0;
    table->active += cls[v] != kIsolated;
    table->total_q += qv;
  }
  table->surface.ids.shrink_to_fit();
  sort_ascending(table->surface.ids, q);
  sort_ascending(table->curve.ids, q);
  // Prefix sums, in order (their last bits are part of the result).
  table->curve.root = true;
  table->surface.sum_up(q);
  table->curve.sum_up(q);
  layout.sampling_table.set(table);
  return table;
}

bool has_per_vertex_guidance(const SamplingParams& params) {
  return params.guidance || !params.boxes.empty() || params.view.enabled;
}

// Guidance u per vertex (boxes override the painted value): the density multiplier m(u) =
// ((1 + u) / (1 - u))^2, so u = 0.5 asks for 9 times the density, -0.5 for a ninth; u = 1 is
// a control point (kForced), u = -1 never sampled (0). A multiplier, not a probability, so
// paint redistributes the budget: the rate is solved so the probabilities still sum to the
// target (more here means less elsewhere).
}  // namespace

double guidance_multiplier(double u) {
  // Within 1/256 of +-1 (what 8-bit painted colours can reach) is a hard keep or drop.
  if (u >= 1.0 - 1.0 / 256.0) return kForcedMultiplier;
  if (u <= -1.0 + 1.0 / 256.0) return 0.0;
  return u == 0.0 ? 1.0 : std::pow((1.0 + u) / (1.0 - u), 2.0);
}

std::vector<double> guidance_multipliers(const Mesh& mesh, const SamplingParams& params) {
  const int32_t n = mesh.num_vertices();
  std::vector<double> m(n, 1.0);
  if (!has_multipliers(params)) return m;
  parallel_for(0, n, kParallelMin, [&](int32_t v) {
    double u = params.guidance ? params.guidance[mesh.vertex_source()[v]] : 0.0;
    for (const auto& box : params.boxes)
      if (inside_box(box, mesh.position(v))) u = box.value;
    m[v] = guidance_multiplier(u);
  });
  return m;
}

namespace {

double surface_probability(const Mesh& mesh, const SamplingParams& params, int32_t v, double k, double q,
                           double multiplier) {
  if (multiplier == kForcedMultiplier) return 1.0;  // a control point
  if (multiplier <= 0.0) return 0.0;      // never sampled (topology may still need it)
  double p = std::min(1.0, k * q * multiplier);
  if (params.view.enabled) p = apply_view(params.view, mesh.position(v), &mesh.normals()[3 * size_t(v)], p);
  return std::clamp(p, 0.0, 1.0);
}

std::vector<double> probabilities(const Mesh& mesh, const ImportanceTable& table,
                                  const std::vector<double>& multiplier, const SamplingParams& params, double k) {
  const int32_t n = mesh.num_vertices();
  const auto& cls = table.cls;
  const Importance q = importance(mesh, table);
  std::vector<double> p(n);
  const bool guided = has_per_vertex_guidance(params);
  parallel_for(0, n, kParallelMin, [&](int32_t v) {
    if (!guided || cls[v] == kIsolated || cls[v] == kCorner) {
      p[v] = plain_probability(cls[v], q(v), k);
    } else {
      const double surface = surface_probability(mesh, params, v, k, q(v), multiplier[v]);
      p[v] = cls[v] == kCurve ? std::sqrt(surface) : surface;
    }
  });
  return p;
}

// With guidance: the base rate k whose guided probabilities sum to the target. The sum only
// grows with k; it is bracketed by doubling, then found by regula falsi (Illinois variant),
// each step one parallel pass over the vertices. When the forced vertices alone exceed the
// target, k = 0 (the count is then theirs, reported as over budget).
double solve_guided_rate(const Mesh& mesh, const ImportanceTable& table, const std::vector<double>& multiplier,
                         const SamplingParams& params, double target) {
  auto excess = [&](double k) {
    const auto p = probabilities(mesh, table, multiplier, params, k);
    double sum = 0.0;
    for (double x : p) sum += x;
    return sum - target;
  };
  const double tolerance = std::max(0.5, 1e-4 * target);
  double lo = 0.0, f_lo = excess(0.0);
  if (f_lo >= -tolerance) return 0.0;
  double hi = std::max(1e-12, target / std::max<double>(1.0, double(mesh.num_vertices())));
  double f_hi = excess(hi);
  for (int i = 0; f_hi < 0 && i < 200; ++i) {
    lo = hi, f_lo = f_hi;
    hi *= 2.0;
    f_hi = excess(hi);
  }
  if (f_hi <= tolerance) return hi;  // everything that can be sampled is
  int side = 0;
  for (int it = 0; it < 60; ++it) {
    double k = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
    if (!(k > lo && k < hi)) k = 0.5 * (lo + hi);
    const double f = excess(k);
    if (std::abs(f) <= tolerance) return k;
    if (f < 0) {
      lo = k, f_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = k, f_hi = f;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    }
  }
  return 0.5 * (lo + hi);
}

// Without guidance: the base rate k whose probabilities sum to the target. The sum is
// increasing and concave in k (min(1, k q) and sqrt are), so Newton steps taken from below stay
// below the root and converge monotonically; a bracket guards against round-off. The draw
// fixes the count anyway, so k need only be close. Each evaluation reads the sorted q and
// their prefix sums: the vertices with k q < 1 are a prefix, the rest count 1 each.
// The sum of the probabilities without guidance at rate k (the expected sample count), and
// its derivative.
double expected_count(const ImportanceTable& table, const Importance& q, double k, double& slope) {
  const size_t surfaces = table.surface.size(), curves = table.curve.size();
  const double limit = k > 0 ? 1.0 / k : std::numeric_limits<double>::infinity();
  const size_t s = table.surface.count_below(q, limit), c = table.curve.count_below(q, limit);
  const double root = std::sqrt(k), surface_sum = table.surface.sum_before(q, s),
               curve_sum = table.curve.sum_before(q, c);
  slope = surface_sum + (k > 0 ? 0.5 * curve_sum / root : 0.0);
  return table.corners + k * surface_sum + double(surfaces - s) + root * curve_sum + double(curves - c);
}

double solve_rate(const ImportanceTable& table, const Importance& q, double target) {
  double min_q = 1e300;
  if (table.surface.size() > 0) min_q = std::min(min_q, q(table.surface.ids.front()));
  if (table.curve.size() > 0) min_q = std::min(min_q, q(table.curve.ids.front()));
  auto evaluate = [&](double k, double& slope) { return expected_count(table, q, k, slope); };
  if (table.total_q <= 0 || target <= table.corners) return 0.0;
  double lo = 0.0, hi = min_q < 1e300 ? 1.0 / min_q : 1.0;
  double slope = 0.0;
  if (evaluate(hi, slope) <= target) return hi;
  // Start from the rate that would be exact if nothing clamped and there were no curves; the
  // curves' sqrt makes the true sum larger, so this start is at or below the root... unless
  // clamping dominates, which the bracket handles.
  double k = std::min(hi, (target - table.corners) / table.total_q);
  for (int it = 0; it < 50; ++it) {
    const double f = evaluate(k, slope) - target;
    if (std::abs(f) <= std::max(0.5, 1e-4 * target)) break;
    if (f < 0) lo = k;
    else hi = k;
    double next = slope > 0 ? k - f / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    k = next;
  }
  return k;
}

// This seed's uniforms. The first draw with a seed only notes it and hashes each vertex where it
// is read (a single decimation never keeps n doubles for it); a second draw with the same seed
// (a slider) makes them and keeps them on the layout; `reused` from then on.
std::shared_ptr<const SelectionUniforms> selection_uniforms(const Mesh& mesh, const FeatureLayout& layout,
                                                            uint64_t seed, bool& reused) {
  auto cached = std::static_pointer_cast<const SelectionUniforms>(layout.selection_uniforms.get());
  const int32_t n = mesh.num_vertices();
  reused = cached && cached->seed == seed && int32_t(cached->u.size()) == n;
  if (reused) return cached;
  auto table = std::make_shared<SelectionUniforms>();
  table->seed = seed;
  table->vertex_source = mesh.vertex_source().data();
  if (cached && cached->seed == seed) {  // the second draw with this seed: a slider's, as before
    reused = true;
    table->u.resize(n);
    parallel_for(0, n, kParallelMin, [&](int32_t v) { table->u[v] = table->hashed(v); });
  }
  layout.selection_uniforms.set(table);
  return table;
}

// Candidates with Pareto key (U / (1 - U)) ((1 - p) / p) below `threshold`, in vertex order;
// probability(v) gives p. The same pass gives the vertices with p = 1 (in vertex order) and the
// sum of all p (the same to the bit for any thread count) when asked for.
template <typename Probability>
std::vector<Candidate> pareto_candidates(const Mesh& mesh, const SelectionUniforms& uniforms,
                                         const Probability& probability, double threshold,
                                         std::vector<int32_t>* forced = nullptr, double* sum = nullptr) {
  struct Found {
    double sum = 0.0;
    std::vector<int32_t> forced;
    std::vector<Candidate> candidates;
  };
  Found found = ordered_reduce<Found>(
      mesh.num_vertices(),
      [&](Found& block, int64_t i) {
        const int32_t v = int32_t(i);
        const double pv = probability(v);
        block.sum += pv;
        if (pv >= 1.0 && forced) block.forced.push_back(v);
        double key;
        if (pv > 0.0 && pv < 1.0 && pareto_key_below(uniforms.at(v), pv, threshold, key))
          block.candidates.push_back({key, v});
      },
      [](Found& total, const Found& block) {
        total.sum += block.sum;
        total.forced.insert(total.forced.end(), block.forced.begin(), block.forced.end());
        total.candidates.insert(total.candidates.end(), block.candidates.begin(), block.candidates.end());
      });
  if (forced) *forced = std::move(found.forced);
  if (sum) *sum = found.sum;
  return std::move(found.candidates);
}

// Sorts distinct vertex ids in [0, n): a bit per vertex, read back in order (a tenth of the cost of
// std::sort for a 10 % sample of a million vertices).
void sort_vertex_ids(std::vector<int32_t>& ids, int32_t n) {
  if (ids.size() < 4096) {
    std::sort(ids.begin(), ids.end());
    return;
  }
  IdBits bits(n);
  for (int32_t v : ids)
    if (!bits.insert(v)) {  // a repeated id would be lost: sort the plain way
      std::sort(ids.begin(), ids.end());
      return;
    }
  size_t at = 0;
  bits.for_each([&](int32_t v) { ids[at++] = v; });
}

// Breadth-first ball of `rings` hops around `center`, restricted by `follow(slot)`; calls
// visit(v) for each vertex reached (center included).
template <class Follow, class Visit>
void ring_ball(const Mesh& mesh, int32_t center, int32_t rings, std::vector<int32_t>& stamp, int32_t stamp_id,
               std::vector<int32_t>& queue, Follow follow, Visit visit) {
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  queue.clear();
  queue.push_back(center);
  stamp[center] = stamp_id;
  size_t head = 0;
  for (int32_t ring = 0; ring <= rings && head < queue.size(); ++ring) {
    const size_t end = queue.size();
    for (; head < end; ++head) {
      const int32_t v = queue[head];
      visit(v);
      if (ring == rings) continue;
      for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
        const int32_t u = adj[i];
        if (stamp[u] != stamp_id && follow(v, i, u)) {
          stamp[u] = stamp_id;
          queue.push_back(u);
        }
      }
    }
  }
}

double mean_edge_length(const Mesh& mesh) {
  const auto& ev = mesh.edge_vertices();
  const int32_t m = mesh.num_edges();
  std::vector<double> length(m);
  parallel_for(0, m, kParallelMin, [&](int32_t e) {
    const double* a = mesh.position(ev[2 * e]);
    const double* b = mesh.position(ev[2 * e + 1]);
    length[e] = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  });
  // Summed in edge order on one thread: a reduction's order, and so its last bits, would depend
  // on the number of threads.
  double total = 0.0;
  for (double l : length) total += l;
  return m ? total / m : 0.0;
}

// Poisson-disk rejection (thesis 4.1.2): candidates in key order, each accepted sample blocks
// its neighbourhood. Surface samples block surface vertices; curve samples and corners block
// both, so borders keep their own spacing. Stops at `count` samples; if rejection leaves too
// few, the rejected candidates are taken back in key order.
template <class AllCandidates>
std::vector<int32_t> select_with_density(const Mesh& mesh, const FeatureLayout& layout,
                                         const std::vector<uint8_t>& cls, const SamplingParams& params,
                                         std::vector<int32_t> forced, std::vector<Candidate> candidates,
                                         AllCandidates all_candidates, int32_t count, int32_t& rejected_out) {
  const int32_t n = mesh.num_vertices();
  const double r = std::sqrt(double(std::max<int32_t>(1, n)) / (3.0 * std::max<int32_t>(1, count)));
  const int32_t eps_uniform = params.density_rings > 0 ? params.density_rings : std::max(1, int32_t(std::lround(r)));
  const int32_t eps_big = params.density_rings > 0 ? params.density_rings : std::max(2, int32_t(std::lround(1.25 * r)));
  const int32_t eps_small = std::max(1, int32_t(eps_big / std::max(1.0, params.density_ratio)));
  const double eps_euclid = params.density_epsilon > 0 ? params.density_epsilon : r * mean_edge_length(mesh);
  const auto& ae = mesh.adjacency_edge();

  std::vector<uint8_t> blocked(n, 0);
  std::vector<int32_t> stamp(n, -1), queue;
  int32_t stamp_id = 0;
  auto block_around = [&](int32_t s) {
    const bool surface = cls[s] == kSurface;
    int32_t rings = eps_uniform;
    if (params.density == DensityMode::Adaptive)
      rings = mesh.weights()[s] > mesh.mean_weight() ? eps_small : eps_big;
    const double* ps = mesh.position(s);
    const bool euclid = params.density == DensityMode::Euclidean;
    const int32_t max_rings = euclid ? n : rings;
    ++stamp_id;
    // Surface samples spread over surface vertices only; border samples along borders and into the surface.
    ring_ball(
        mesh, s, max_rings, stamp, stamp_id, queue,
        [&](int32_t, int32_t slot, int32_t u) {
          if (euclid) {
            const double* pu = mesh.position(u);
            const double d2 = (pu[0] - ps[0]) * (pu[0] - ps[0]) + (pu[1] - ps[1]) * (pu[1] - ps[1]) +
                              (pu[2] - ps[2]) * (pu[2] - ps[2]);
            if (d2 > eps_euclid * eps_euclid) return false;
          }
          if (surface) return !layout.is_feature_vertex(u);
          return layout.is_feature_vertex(u) ? layout.is_feature_edge(ae[slot]) : true;
        },
        [&](int32_t v) { blocked[v] = 1; });
  };
  std::vector<int32_t> chosen = std::move(forced);
  for (int32_t s : chosen) block_around(s);
  std::vector<Candidate> skipped;
  // Sort candidates lazily in chunks: usually only the first ~2 count are ever looked at.
  size_t sorted_end = 0;
  auto ensure_sorted = [&](size_t i) {
    if (i < sorted_end) return;
    const size_t chunk = std::max<size_t>(2 * size_t(count) + 64, sorted_end);
    const size_t end = std::min(candidates.size(), sorted_end + chunk);
    std::nth_element(candidates.begin() + sorted_end, candidates.begin() + (end - 1), candidates.end());
    std::sort(candidates.begin() + sorted_end, candidates.begin() + end);
    sorted_end = end;
  };
  int32_t rejected = 0;
  bool complete = false;  // candidates holds every vertex with 0 < p < 1
  for (size_t i = 0; int32_t(chosen.size()) < count; ++i) {
    if (i == candidates.size()) {
      if (complete) break;
      // The kept superset ran out: continue with the candidates it did not hold, in key order.
      std::vector<Candidate> everything = all_candidates();
      std::sort(everything.begin(), everything.end());
      const Candidate last = i > 0 ? candidates[i - 1] : Candidate{-1.0, -1};
      std::vector<Candidate> rest;
      for (const auto& c : everything)
        if (last < c) rest.push_back(c);
      candidates.resize(i);
      candidates.insert(candidates.end(), rest.begin(), rest.end());
      sorted_end = candidates.size();
      complete = true;
      if (i == candidates.size()) break;
    }
    ensure_sorted(i);
    const int32_t v = candidates[i].vertex;
    if (blocked[v]) {
      ++rejected;
      skipped.push_back(candidates[i]);
      continue;
    }
    chosen.push_back(v);
    block_around(v);
  }
  for (size_t i = 0; i < skipped.size() && int32_t(chosen.size()) < count; ++i) {
    chosen.push_back(skipped[i].vertex);
    --rejected;
  }
  rejected_out = rejected;
  return chosen;
}

}  // namespace

bool is_guided(const Mesh& mesh, const SamplingParams& params) {
  if (params.view.enabled || !params.boxes.empty()) return true;
  if (params.guidance)
    for (int32_t v = 0; v < mesh.num_vertices(); ++v)
      if (params.guidance[v] != 0.0) return true;  // indexed by caller id; any order will do
  return false;
}

void validate_sampling_params(const Mesh& mesh, const SamplingParams& params) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument(message);
  };
  require(params.adaptivity >= 0.0 && params.adaptivity <= 1.0, "adaptivity must lie in [0, 1]");
  require(params.flat_floor >= 0.0 && params.flat_floor <= 1.0, "flat_floor must lie in [0, 1]");
  require(params.density_rings >= 0, "density_rings must be >= 0");
  require(params.density_ratio >= 1.0, "density_ratio must be >= 1");
  require(params.density_epsilon >= 0.0 && std::isfinite(params.density_epsilon), "density_epsilon must be >= 0");
  if (params.guidance)
    for (int32_t v = 0; v < mesh.num_vertices(); ++v) {
      const double u = params.guidance[v];
      if (!(u >= -1.0 && u <= 1.0))
        throw std::invalid_argument("guidance of vertex " + std::to_string(v) + " is " + std::to_string(u) +
                                    "; it must lie in [-1, 1]");
    }
  for (size_t b = 0; b < params.boxes.size(); ++b) {
    const auto& box = params.boxes[b];
    require(box.value >= -1.0 && box.value <= 1.0, "box " + std::to_string(b) + " guidance must lie in [-1, 1]");
    for (double x : box.world_to_box) require(std::isfinite(x), "box " + std::to_string(b) + " matrix is not finite");
  }
  if (params.view.enabled) {
    const auto& view = params.view;
    require(view.back_ratio >= 0.0 && view.back_ratio <= 1.0, "view back_ratio must lie in [0, 1]");
    require(view.silhouette_angle >= 0.0 && view.silhouette_angle <= kPi, "silhouette angle must lie in [0, pi]");
    require(view.silhouette_falloff >= 0.0, "silhouette falloff must be >= 0");
    require(view.outside_probability >= 0.0 && view.outside_probability <= 1.0,
            "outside-frustum probability must lie in [0, 1]");
    double d2 = 0;
    for (double x : view.direction) d2 += x * x;
    require(view.perspective || d2 > 0, "view direction must not be zero");
    for (double x : view.eye) require(std::isfinite(x), "view eye position is not finite");
    for (double x : view.view_projection) require(std::isfinite(x), "view-projection matrix is not finite");
  }
}

std::vector<double> sampling_probabilities(const Mesh& mesh, const FeatureLayout& layout,
                                           const SamplingParams& params, double k) {
  const auto table = importance_table(mesh, layout, params);
  return probabilities(mesh, *table, guidance_multipliers(mesh, params), params, k);
}

// Joins the vertices of `kept` (sorted) that are not forced already to the forced vertices.
void join_forced(const std::vector<int32_t>& kept, std::vector<int32_t>& forced) {
  if (kept.empty()) return;
  std::vector<int32_t> already = forced;  // a control point or a corner may be among them
  std::sort(already.begin(), already.end());
  for (int32_t v : kept)
    if (!std::binary_search(already.begin(), already.end(), v)) forced.push_back(v);
}

// Joins `more` (sorted) to `kept` (sorted, for drop_kept) and, those not forced already, to the
// forced vertices.
void keep_and_force(const std::vector<int32_t>& more, std::vector<int32_t>& kept, std::vector<int32_t>& forced) {
  if (more.empty()) return;
  join_forced(more, forced);
  std::vector<int32_t> joined;
  std::set_union(kept.begin(), kept.end(), more.begin(), more.end(), std::back_inserter(joined));
  kept = std::move(joined);
}

// The border vertices the draw keeps, joined to the forced vertices (unless never sampled). With
// keep_curves (a first pass the collapses thin next) every feature curve vertex, while they are at
// most a quarter of the count: a random gap on a border is a notch the collapses cannot fill (a
// fractal terrain's rim lost a valley of 0.13 % of its diagonal between samples 18 edges apart);
// the collapses then thin the curves in cost order. Otherwise, or when the curves hold more, the
// layout's sharpest bends, up to an eighth of the count: a random gap at a bend cuts the border's
// corner off, by up to half the gap (a box-cut isosurface lost 0.5 % of its diagonal so). Returns
// them sorted, for drop_kept.
template <class Probability>
std::vector<int32_t> force_curves(const FeatureLayout& layout, int32_t count, bool keep_curves,
                                  const Probability& probability, std::vector<int32_t>& forced) {
  std::vector<int32_t> kept;
  if (keep_curves && layout.curve_vertices.size() <= size_t(std::max(0, count / 4))) {
    for (int32_t v : layout.curve_vertices)
      if (probability(v) > 0.0) kept.push_back(v);
    std::sort(kept.begin(), kept.end());
    kept.erase(std::unique(kept.begin(), kept.end()), kept.end());  // curves share their corners
  } else {
    const size_t take = std::min(layout.curve_bends.size(), size_t(std::max(0, count / 8)));
    for (size_t i = 0; i < take; ++i)
      if (probability(layout.curve_bends[i]) > 0.0) kept.push_back(layout.curve_bends[i]);
    std::sort(kept.begin(), kept.end());
  }
  join_forced(kept, forced);
  return kept;
}

// The corners of triangles that stay whole, joined to the forced vertices and to `kept` (for
// drop_kept): triangles that are pieces of their own (FeatureLayout::loose_vertices; a draw
// without them only sends the repairs after them round by round: 327,680 loose triangles, 7.7 s
// in fast mode) and the winding seam's (FeatureLayout::winding_seam_vertices).
// Returns how many the winding seam added (no border's corners: DecimateResult::loop_forced).
int32_t force_whole_triangles(const FeatureLayout& layout, std::vector<int32_t>& kept, std::vector<int32_t>& forced) {
  keep_and_force(layout.loose_vertices, kept, forced);
  const size_t before = forced.size();
  keep_and_force(layout.winding_seam_vertices, kept, forced);
  return int32_t(forced.size() - before);
}

// Each boundary loop too short to expect three samples at this count (FeatureLayout::
// boundary_loop_vertices) keeps three, spread over its vertices (sorted by id, which follows
// space), joined to the forced vertices and to `kept`, where such loops are many (their three
// at least a quarter of the count): a hole met by fewer clusters closes up, and the partition
// check's repairs found them one sample per loop and round (a scan's thousands of small holes
// took round after round). A few are left to the repairs, which take them in a round or two
// and leave the budget to the draw (forced, a painted dragon's two tiny holes drew top-ups into
// its Less region). Returns how many it forced.
template <class Probability>
int32_t force_boundary_loops(const FeatureLayout& layout, int32_t count, int32_t active,
                             const Probability& probability, std::vector<int32_t>& kept, std::vector<int32_t>& forced) {
  const int32_t loops = int32_t(layout.boundary_loop_offsets.size()) - 1;
  if (loops <= 0) return 0;
  const double per_vertex = double(count) / double(std::max(1, active));
  std::vector<int32_t> already = forced;  // corners and control points count as kept
  std::sort(already.begin(), already.end());
  std::vector<int32_t> added;
  for (int32_t loop = 0; loop < loops; ++loop) {
    const int32_t b = layout.boundary_loop_offsets[loop], n = layout.boundary_loop_offsets[loop + 1] - b;
    if (n < 3 || double(n) * per_vertex >= 3.0) continue;
    const int32_t* vertices = &layout.boundary_loop_vertices[size_t(b)];
    int32_t have = 0;
    for (int32_t i = 0; i < n && have < 3; ++i)
      have += std::binary_search(kept.begin(), kept.end(), vertices[i]) ||
              std::binary_search(already.begin(), already.end(), vertices[i]);
    for (int32_t k = 0; k < 3 && have < 3; ++k) {
      const int32_t v = vertices[k * n / 3];
      if (probability(v) > 0.0 && !std::binary_search(kept.begin(), kept.end(), v) &&
          !std::binary_search(already.begin(), already.end(), v))
        added.push_back(v), ++have;
    }
  }
  std::sort(added.begin(), added.end());
  added.erase(std::unique(added.begin(), added.end()), added.end());  // loops touching at a pinch
  if (added.empty() || 4 * int64_t(added.size()) < int64_t(count)) return 0;
  keep_and_force(added, kept, forced);
  return int32_t(added.size());
}

// Removes the kept border vertices (sorted) from the candidates.
void drop_kept(const std::vector<int32_t>& kept, std::vector<Candidate>& candidates) {
  if (kept.empty()) return;
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [&kept](const Candidate& c) {
                                    return std::binary_search(kept.begin(), kept.end(), c.vertex);
                                  }),
                   candidates.end());
}

SampleSet select_samples(const Mesh& mesh, const FeatureLayout& layout, const SamplingParams& params,
                         int32_t target_vertices) {
  validate_sampling_params(mesh, params);
  const int32_t n = mesh.num_vertices();
  const auto table = importance_table(mesh, layout, params);
  const auto& cls = table->cls;
  const int32_t active = table->active;
  SampleSet out;
  out.guided = is_guided(mesh, params);
  const int32_t target = std::clamp(target_vertices, 0, active);
  // Multipliers are read only with per-vertex guidance (all ones otherwise: not made).
  const auto multiplier = has_per_vertex_guidance(params) ? guidance_multipliers(mesh, params) : std::vector<double>();
  out.rate = out.guided ? solve_guided_rate(mesh, *table, multiplier, params, target) : solve_rate(*table, importance(mesh, *table), target);
  // The draw takes exactly the target, guided or not; only vertices with p = 1 (corners,
  // control points) can push it over.
  const int32_t count = target;
  const bool density = params.density != DensityMode::Off;
  bool uniforms_reused = false;
  const auto uniforms = selection_uniforms(mesh, layout, params.seed, uniforms_reused);
  const bool plain = !has_per_vertex_guidance(params);
  // (The order's pass gives the candidates of the first threshold only.)
  const auto order = plain && !density ? candidate_order(mesh, layout, table, *uniforms, uniforms_reused) : nullptr;
  auto draw = [&](const auto& probability) {
    // Pareto keys: with threshold 1 the expected number of keys below it is exactly the sum of
    // the probabilities, so a slightly larger threshold keeps a small superset of what the draw
    // needs; if it falls short (tiny targets), the threshold grows. The first pass also finds
    // the forced vertices (and, with guidance, the expected count). A slider's later draws
    // find the same in the kept order.
    const double first_threshold = density ? 3.0 : kFirstThreshold;
    std::vector<int32_t> forced;
    std::vector<Candidate> candidates;
    if (order) candidates_in_order(*order, out.rate, forced, candidates);
    else candidates = pareto_candidates(mesh, *uniforms, probability, first_threshold, &forced, plain ? nullptr : &out.expected);
    // Without guidance the sum of the probabilities comes from the table: the same value
    // whichever way the candidates were found.
    double slope;
    if (plain) out.expected = expected_count(*table, importance(mesh, *table), out.rate, slope);
    auto kept = force_curves(layout, count, params.keep_curves, probability, forced);
    const int32_t seam_forced = force_whole_triangles(layout, kept, forced);
    out.loop_forced = seam_forced + force_boundary_loops(layout, count, mesh.num_vertices() - mesh.report().isolated_vertices,
                                           probability, kept, forced);
    drop_kept(kept, candidates);
    // The candidates below a threshold, the kept border vertices left out.
    auto candidates_below = [&](double threshold) {
      auto found = pareto_candidates(mesh, *uniforms, probability, threshold);
      drop_kept(kept, found);
      return found;
    };
    out.forced = static_cast<int32_t>(forced.size());
    const int32_t free_count = std::max<int32_t>(0, count - out.forced);
    // (Nothing to widen when the forced vertices fill the count: ten passes found no candidate
    // at rate 0.)
    for (double threshold = first_threshold;
         free_count > 0 && threshold <= 1e6 && int64_t(candidates.size()) < int64_t(density ? 2 : 1) * free_count + 16;) {
      threshold *= 4;
      candidates = candidates_below(threshold);
    }
    if (!density) {
      out.samples = std::move(forced);
      const size_t take = std::min<size_t>(free_count, candidates.size());
      if (take > 0) {
        std::nth_element(candidates.begin(), candidates.begin() + (take - 1), candidates.end());
        for (size_t i = 0; i < take; ++i) out.samples.push_back(candidates[i].vertex);
      }
    } else {
      // Density control may reject many candidates: if the kept superset runs out, take all.
      auto all = [&]() { return candidates_below(std::numeric_limits<double>::infinity()); };
      out.samples = select_with_density(mesh, layout, cls, params, std::move(forced), std::move(candidates), all,
                                        std::max(count, out.forced), out.density_rejected);
    }
  };
  if (plain) {
    // Without per-vertex guidance p is a formula of the class, q and the rate: computed where
    // it is read instead of written to and read back from n doubles (a slider draws anew for
    // every frame).
    const Importance q = importance(mesh, *table);
    const double rate = out.rate;
    draw([&cls, &q, rate](int32_t v) { return plain_probability(cls[v], q(v), rate); });
  } else {
    const auto p = probabilities(mesh, *table, multiplier, params, out.rate);
    draw([&p](int32_t v) { return p[v]; });
  }
  sort_vertex_ids(out.samples, n);
  return out;
}

}  // namespace topstoc
