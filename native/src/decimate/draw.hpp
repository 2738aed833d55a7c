// What the seeded draw of sampling.cpp shares with candidate_order.cpp: the vertex classes, the
// importance table and a seed's uniforms (both kept on the feature layout), a vertex's
// probability without guidance, and the Pareto key test.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "topstoc/core/random.hpp"

namespace topstoc {
class Mesh;
}

namespace topstoc::draw {

enum VertexClass : uint8_t { kIsolated = 0, kSurface = 1, kCurve = 2, kCorner = 3 };

struct Candidate {
  double key;
  int32_t vertex;
  bool operator<(const Candidate& o) const { return key < o.key || (key == o.key && vertex < o.vertex); }
};

// Vertices in ascending order of a value computed where read (value(v), the importance), and
// the running sum of their terms (the value, or its square root), kept at every kStride-th
// entry only: sum_before(s) adds the few terms after the last kept sum in the same order as a
// full running sum would, so it gives the same bits with n / 64 doubles instead of n (the full
// sums were a twentieth of a large decimation's peak). Vertex ids instead of the sorted values
// themselves: 4 bytes a vertex instead of 8 kept on the layout.
struct SortedSums {
  static constexpr size_t kStride = 64;
  std::vector<int32_t> ids;
  bool root = false;  // terms are sqrt(value)
  std::vector<double> kept;  // kept[j]: the sum of the terms before entry j * kStride

  size_t size() const { return ids.size(); }
  template <class Value>
  double term(const Value& value, size_t i) const {
    return root ? std::sqrt(value(ids[i])) : value(ids[i]);
  }
  template <class Value>
  void sum_up(const Value& value) {
    kept.assign(ids.size() / kStride + 1, 0.0);
    double sum = 0.0;
    for (size_t i = 0; i < ids.size(); ++i) {
      sum += term(value, i);
      if ((i + 1) % kStride == 0) kept[(i + 1) / kStride] = sum;
    }
  }
  /// The sum of the terms of entries 0..s-1 (0 <= s <= size()).
  template <class Value>
  double sum_before(const Value& value, size_t s) const {
    double sum = kept[s / kStride];
    for (size_t i = s / kStride * kStride; i < s; ++i) sum += term(value, i);
    return sum;
  }
  /// How many values lie below `limit`.
  template <class Value>
  size_t count_below(const Value& value, double limit) const {
    return std::partition_point(ids.begin(), ids.end(), [&](int32_t v) { return value(v) < limit; }) - ids.begin();
  }
};

// Per-vertex class and importance q (0 where not sampled stochastically), with q sorted per
// class for solving the rate. Depends on the mesh, the layout and three parameters only, so it
// is kept on the layout and reused while they stay the same (a slider changes only the target).
struct ImportanceTable {
  double adaptivity = 0.0, flat_floor = 0.0;
  bool area_weighted = false;
  std::vector<uint8_t> cls;
  SortedSums surface;  // the surface vertices by q, q summed
  SortedSums curve;    // the curve vertices by q, the square roots of q summed
  double corners = 0.0;
  double total_q = 0.0;  // over surface and curve vertices
  int32_t active = 0;    // vertices in triangles
};

// Importance q(v) = 1 + α (x / x̄ - 1), floored so flat regions are not starved; 0 for vertices
// not sampled stochastically (isolated, corners). With area weighting q is also scaled by the
// vertex's area over the mean, so that samples per unit area, not per vertex, follow the weights
// on irregularly tessellated meshes. Computed where read from the mesh's weights (a table of
// them was n doubles kept on the layout).
class Importance {
 public:
  /// weights: the mesh's importance weights and their mean; area: the vertex areas and their
  /// mean, or null without area weighting.
  Importance(const ImportanceTable& table, const double* weights, double mean_weight, const double* area,
             double mean_area)
      : table_(table), weights_(weights), area_(area), mean_weight_(mean_weight), mean_area_(mean_area) {}

  double operator()(int32_t v) const {
    const uint8_t cls = table_.cls[v];
    if (cls != kSurface && cls != kCurve) return 0.0;
    const double mean = mean_weight_;
    const double q = std::max(mean > 0 ? 1.0 + table_.adaptivity * (weights_[v] / mean - 1.0) : 1.0, table_.flat_floor);
    return area_ ? q * area_[v] / mean_area_ : q;
  }

 private:
  const ImportanceTable& table_;
  const double* weights_;
  const double* area_;
  double mean_weight_, mean_area_;
};

/// The importance of `table`'s vertices on `mesh` (sampling.cpp).
Importance importance(const Mesh& mesh, const ImportanceTable& table);

// The uniform U of every vertex for one seed (it depends on the seed and the vertex's caller id
// only), kept with the layout for the seed drawn last: a slider's draws read them instead of
// hashing every vertex again (a tenth of a draft's time).
// The random stream of the selection's uniforms.
constexpr uint64_t kStreamSelection = 1;

struct SelectionUniforms {
  uint64_t seed = 0;
  std::vector<double> u;  // empty until a second draw with this seed (sampling.cpp)
  const int32_t* vertex_source = nullptr;  // the mesh's caller ids, for hashing

  double hashed(int32_t v) const { return uniform01(seed, kStreamSelection, uint64_t(vertex_source[v])); }
  double at(int32_t v) const { return u.empty() ? hashed(v) : u[v]; }
};

// The draw's first Pareto threshold without density control. With 1, the expected number of
// keys below it is the target; a little more keeps a small superset of what the draw takes.
constexpr double kFirstThreshold = 1.25;

// A vertex's probability at rate k from its class and importance, without per-vertex guidance.
inline double plain_probability(uint8_t cls, double q, double k) {
  switch (cls) {
    case kIsolated: return 0.0;
    case kCorner: return 1.0;
    default: {
      const double surface = std::min(1.0, k * q);
      return cls == kCurve ? std::sqrt(surface) : surface;
    }
  }
}

// True when a vertex of uniform u and probability pv (0 < pv < 1) has its Pareto key
// (u / (1 - u)) ((1 - pv) / pv) below `threshold`; the key is set then.
inline bool pareto_key_below(double u, double pv, double threshold, double& key) {
  // key < threshold without the two divisions (most vertices fail it); the key itself is
  // computed as before for those that pass. A vertex whose rounding differs sits at the
  // threshold, far above the keys the draw takes (the threshold leaves a margin).
  if (u * (1.0 - pv) >= threshold * pv * (1.0 - u)) return false;
  key = (u / (1.0 - u)) * ((1.0 - pv) / pv);
  return key < threshold;
}

}  // namespace topstoc::draw
