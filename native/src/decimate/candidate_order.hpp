// The vertices in the order a slider's draws take them (sampling.cpp, docs/design.md §2.3).
//
// A slider draws again and again with one seed at changing rates k. Without guidance, a
// vertex's key falls below the draw's first threshold T exactly when k exceeds
//   r(v) = p* / q(v) on a surface, p*^2 / q(v) on a curve, where p* = U / (U + T (1 - U))
// (the key is below T when p > p*, and p = k q or sqrt(k q)). So, with the vertices ordered by
// r, the candidates at any rate are among a prefix: a draw tests those (about an eighth of the
// vertices at 10 %) with the same test as the pass over all vertices, and finds
// the same candidates. Ordered by buckets of r, each in vertex order, with each vertex's U and
// q alongside: read in this order from the per-vertex arrays, the prefix cost more than a pass
// over every vertex.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "decimate/draw.hpp"
#include "topstoc/core/buffer.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/features.hpp"

namespace topstoc::draw {

struct CandidateOrder {
  uint64_t seed = 0;
  std::shared_ptr<const ImportanceTable> table;  // the table it was made from
  std::vector<int32_t> corners;                  // always drawn (p = 1)
  std::vector<int32_t> offsets;                  // the first position of every bucket, then the count
  Buffer<int32_t> vertices;                      // surface and curve vertices with q > 0, by bucket of r
  Buffer<double> u;                              // ... their uniforms
  Buffer<double> q;                              // ... their q, negated on a curve
};

/// The order for this seed and table: made on the second draw with the same seed (a slider's),
/// so that a single decimation does not pay for it; null until then.
std::shared_ptr<const CandidateOrder> candidate_order(const Mesh& mesh, const FeatureLayout& layout,
                                                      const std::shared_ptr<const ImportanceTable>& table,
                                                      const SelectionUniforms& uniforms, bool uniforms_reused);

/// What the pass over every vertex with threshold kFirstThreshold finds without guidance: the
/// forced vertices and the candidates, from the order.
void candidates_in_order(const CandidateOrder& order, double rate, std::vector<int32_t>& forced,
                         std::vector<Candidate>& candidates);

}  // namespace topstoc::draw
