// Topological clustering by multi-source breadth-first flood fill (thesis 4.1, algorithm 4.1).
//
// Each vertex joins the sample that minimises (hop distance, rank in the sample list). That
// definition does not depend on the order in which the fill visits vertices, so the result is
// reproducible from the sample list alone, the same serial or parallel, and can be updated
// exactly when samples are added.
// Feature vertices are entered only along feature edges: borders are partitioned as curves of
// their own and no cluster crosses them.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/decimate/features.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

struct Clustering {
  std::vector<int32_t> label;  ///< rank of the vertex's sample, -1 if unreached
  std::vector<int32_t> dist;   ///< hop distance to that sample (INT32_MAX if unreached)
};

/// Floods from `samples` (distinct vertex ids; rank = position). If cross_edges is given it
/// receives every edge between two clusters, once: the faces around them are the candidates
/// of the fast path (thesis 4.1.1), collected during the fill instead of by a later scan.
void flood(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples, Clustering& out,
           std::vector<int32_t>* cross_edges = nullptr);

/// One step from x towards its sample: the lowest-id neighbour in the same cluster one hop
/// closer that the fill could have come from (-1 for a sample).
int32_t step_towards_sample(const Mesh& mesh, const FeatureLayout& layout, const Clustering& clustering, int32_t x);

/// Adds samples[first_new..) to an existing clustering of samples[0..first_new) and updates
/// only the vertices whose (distance, rank) improves. Gives exactly what flood() would.
/// changed, if given, receives every vertex whose label or distance changed.
void flood_add(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
               int32_t first_new, Clustering& clustering, std::vector<int32_t>* changed = nullptr);

}  // namespace topstoc
