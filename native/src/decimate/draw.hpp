// What the seeded draw of sampling.cpp shares with candidate_order.cpp: the vertex classes, the
// importance table and a seed's uniforms (both kept on the feature layout), a vertex's
// probability without guidance, and the Pareto key test.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace topstoc::draw {

enum VertexClass : uint8_t { kIsolated = 0, kSurface = 1, kCurve = 2, kCorner = 3 };

struct Candidate {
  double key;
  int32_t vertex;
  bool operator<(const Candidate& o) const { return key < o.key || (key == o.key && vertex < o.vertex); }
};

// Per-vertex class and importance q (0 where not sampled stochastically), with q sorted per
// class for solving the rate. Depends on the mesh, the layout and three parameters only, so it
// is kept on the layout and reused while they stay the same (a slider changes only the target).
struct ImportanceTable {
  double adaptivity = 0.0, flat_floor = 0.0;
  bool area_weighted = false;
  std::vector<uint8_t> cls;
  std::vector<double> q;
  std::vector<double> surface_q, surface_sum;    // sorted ascending; prefix sums of q
  std::vector<double> curve_q, curve_sqrt_sum;   // sorted ascending; prefix sums of sqrt(q)
  double corners = 0.0;
  double total_q = 0.0;  // over surface and curve vertices
  int32_t active = 0;    // vertices in triangles
};

// The uniform U of every vertex for one seed (it depends on the seed and the vertex's caller id
// only), kept with the layout for the seed drawn last: a slider's draws read them instead of
// hashing every vertex again (a tenth of a draft's time).
struct SelectionUniforms {
  uint64_t seed = 0;
  std::vector<double> u;
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
