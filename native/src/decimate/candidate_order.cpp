#include "decimate/candidate_order.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/counting_sort.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc::draw {

namespace {

constexpr int32_t kRateBuckets = 8 * 20;  // an eighth of a binade each, from 2^-12 to 2^8

// Buckets 9 % wide (the exponent and the top three bits of the mantissa): few enough for one
// cheap counting pass (finer buckets scatter its writes over as many places). Smaller r share
// the first bucket (candidates at any rate a
// slider asks for), larger ones the last.
inline int32_t rate_bucket(double r) {
  uint64_t bits;
  std::memcpy(&bits, &r, sizeof bits);  // r >= 0
  const int64_t eighths = int64_t(bits >> 49) - int64_t(1023 - 12) * 8;
  return int32_t(std::clamp<int64_t>(eighths, 0, kRateBuckets - 1));
}

}  // namespace

std::shared_ptr<const CandidateOrder> candidate_order(const Mesh& mesh, const FeatureLayout& layout,
                                                      const std::shared_ptr<const ImportanceTable>& table,
                                                      const SelectionUniforms& uniforms, bool uniforms_reused) {
  auto cached = std::static_pointer_cast<const CandidateOrder>(layout.candidate_order.get());
  if (cached && cached->seed == uniforms.seed && cached->table == table) return cached;
  if (!uniforms_reused) return nullptr;
  auto order = std::make_shared<CandidateOrder>();
  order->seed = uniforms.seed;
  order->table = table;
  const int32_t n = mesh.num_vertices();
  constexpr int32_t kNone = kRateBuckets;  // not drawn at random: a corner, isolated, or q = 0
  const Importance importance_of = importance(mesh, *table);
  Buffer<uint8_t> bucket(n);
  parallel_for(0, n, kParallelMin, [&](int32_t v) {
    const uint8_t cls = table->cls[v];
    const double q = importance_of(v), u = uniforms.at(v);
    const double p_star = u / (u + kFirstThreshold * (1.0 - u));
    bucket[v] = uint8_t((cls != kSurface && cls != kCurve) || !(q > 0.0) ? kNone
                        : cls == kCurve                                  ? rate_bucket(p_star * p_star / q)
                                                                         : rate_bucket(p_star / q));
  });
  for (int32_t v = 0; v < n; ++v)
    if (table->cls[v] == kCorner) order->corners.push_back(v);
  order->vertices.resize(n);
  order->u.resize(n);
  order->q.resize(n);
  stable_counting_sort(n, kNone + 1, [&](int64_t v) { return bucket[v]; },
                       [&](int64_t v, int32_t at) {
                         order->vertices[at] = int32_t(v);
                         order->u[at] = uniforms.at(int32_t(v));
                         order->q[at] = table->cls[v] == kCurve ? -importance_of(int32_t(v)) : importance_of(int32_t(v));
                       },
                       order->offsets);
  const int32_t drawn = order->offsets[kNone];
  order->vertices.resize(drawn);
  order->u.resize(drawn);
  order->q.resize(drawn);
  order->offsets.resize(kNone + 1);
  layout.candidate_order.set(order);
  return order;
}

void candidates_in_order(const CandidateOrder& order, double rate, std::vector<int32_t>& forced,
                         std::vector<Candidate>& candidates) {
  forced = order.corners;
  // Every vertex whose test can pass has r at most the rate (up to rounding: a margin). One
  // thread: a second one does not make this short loop faster.
  const int32_t end = order.offsets[rate_bucket(rate * (1.0 + 1e-6)) + 1];
  for (int32_t i = 0; i < end; ++i) {
    const double q = order.q[i];
    const double pv = plain_probability(q < 0 ? kCurve : kSurface, std::abs(q), rate);
    double key;
    if (pv >= 1.0) forced.push_back(order.vertices[i]);
    else if (pv > 0.0 && pareto_key_below(order.u[i], pv, kFirstThreshold, key))
      candidates.push_back({key, order.vertices[i]});
  }
}

}  // namespace topstoc::draw
