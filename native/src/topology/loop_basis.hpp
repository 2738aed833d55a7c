// Short simple handle and tunnel loops from the persistence cycles (thesis 3.2.4.2, refined).
//
// Persistence gives g handle and g tunnel cycles: Z2 cycles that span the handle subspace
// (cycles that bound inside) and the tunnel subspace (cycles that bound outside) of H1, but
// that are often long, wiggly and not simple. Any basis of these subspaces made of simple
// loops is an equally valid answer, so this picks short ones greedily, like Erickson and
// Whittlesey's shortest homology basis: candidates are the fundamental cycles of shortest-path
// trees grown from roots spread over the surface (on and near the persistence cycles first)
// and the simple pieces of the persistence cycles; taken shortest first, a candidate is kept
// when its class lies in the handle (tunnel) subspace and is independent of the loops kept so
// far. Every kept loop is a simple closed edge cycle.
//
// The cost follows the size and the genus, not the shape: once the candidates span both
// subspaces, the longest loop they need (the cutoff) bounds every tree to half of it around its
// root; within a tree, the cycles independent of its shorter ones come from union-find on the
// faces (ball_cycles.hpp), not from eliminating their classes; and a new candidate is dropped
// when the picks shorter than it already span its class, so the candidates stay about 2g.
//
// Each loop is then matched to a persistence generator edge: writing the kept handle loops in
// the basis of the handle cycles gives an invertible matrix, whose non-zero diagonal under some
// permutation pairs each loop with the generator of a cycle it contains.
#pragma once

#include <cstdint>
#include <vector>

#include "topology/homology.hpp"
#include "topology/persistence.hpp"
#include "topstoc/core/progress.hpp"
#include "topology/closed_surface.hpp"

namespace topstoc {

struct SelectedLoop {
  bool handle = false;
  std::vector<int32_t> vertices;  ///< simple closed cycle of local vertex ids
  int32_t generator_edge = -1;    ///< the matched persistence generator (local edge id)
  double length = 0.0;            ///< in the given edge weights
};

/// g handle loops then g tunnel loops. edge_weight: per surface edge (length or 1).
/// max_roots: shortest-path trees to grow (0: automatic). Throws std::logic_error if no
/// basis of simple loops is found (not seen in practice; reported rather than guessed).
std::vector<SelectedLoop> select_loops(const ClosedSurface& surface, const SurfaceHomology& homology,
                                       const std::vector<PersistentCycle>& cycles, const std::vector<double>& edge_weight,
                                       int32_t max_roots = 0, Progress* progress = nullptr);

/// Splits a Z2 cycle (edges, each vertex of even degree) into edge-disjoint simple cycles,
/// each a closed vertex sequence.
std::vector<std::vector<int32_t>> simple_cycles(const ClosedSurface& surface, const std::vector<int32_t>& edges);

/// Length of a closed vertex loop in the given edge weights.
double loop_length(const ClosedSurface& surface, const std::vector<int32_t>& loop, const std::vector<double>& edge_weight);

}  // namespace topstoc
