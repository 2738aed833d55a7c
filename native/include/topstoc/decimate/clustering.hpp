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

/// Per vertex, (hop distance, rank of its sample) packed into one word, distance high: one
/// integer comparison orders them as the definition does, and the flood lowers both with one
/// store. The fill writes the words in place, so a flood needs no second copy and no pass to
/// unpack them.
struct Clustering {
  std::vector<uint64_t> key;
  /// Rank of v's sample, -1 if no sample reaches v.
  int32_t label(int32_t v) const { return int32_t(uint32_t(key[v])); }
  /// Hop distance from v to its sample, INT32_MAX if no sample reaches v.
  int32_t dist(int32_t v) const { return int32_t(key[v] >> 32); }
  /// v now belongs to the cluster of rank `rank` (its distance is kept).
  void relabel(int32_t v, int32_t rank) { key[v] = (key[v] & ~uint64_t(0xffffffffu)) | uint32_t(rank); }
  int32_t num_vertices() const { return static_cast<int32_t>(key.size()); }
};

/// The key of a vertex no sample reaches: distance INT32_MAX, rank -1; above every real key.
constexpr uint64_t kUnreachedKey = (uint64_t(INT32_MAX) << 32) | 0xffffffffu;
inline uint64_t cluster_key(int32_t dist, int32_t rank) { return (uint64_t(uint32_t(dist)) << 32) | uint32_t(rank); }

/// Floods from `samples` (distinct vertex ids; rank = position). If cross_edges is given it
/// receives every edge between two clusters, once: the faces around them are the candidates
/// of the fast path (thesis 4.1.1), collected during the fill instead of by a later scan.
void flood(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples, Clustering& out,
           std::vector<int32_t>* cross_edges = nullptr);

/// Turns a clustering of `count` samples (ranks 0..count) into exactly what flood() gives for
/// the first `keep` of them: the clusters of the others are emptied and refilled from around
/// them. A decimation's repairs append samples to its draw: dropping them gives back the flood
/// of the draw, which is what a later decimation at a nearby target starts from.
void flood_drop_tail(const Mesh& mesh, const FeatureLayout& layout, int32_t keep, int32_t count, Clustering& c);

/// One step from x towards its sample: the lowest-id neighbour in the same cluster one hop
/// closer that the fill could have come from (-1 for a sample).
int32_t step_towards_sample(const Mesh& mesh, const FeatureLayout& layout, const Clustering& clustering, int32_t x);

/// Adds samples[first_new..) to an existing clustering of samples[0..first_new) and updates
/// only the vertices whose (distance, rank) improves. Gives exactly what flood() would.
/// changed, if given, receives every vertex whose label or distance changed.
void flood_add(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
               int32_t first_new, Clustering& clustering, std::vector<int32_t>* changed = nullptr);

/// Turns the clustering of old_samples into exactly what flood() gives for `samples` (both
/// increasing vertex ids; ranks are positions): kept clusters take their new ranks, removed
/// ones are refilled from around them, added samples relax outwards. Nearby targets of one
/// decimation share most samples (a slider step replaces a few percent), so most of the mesh
/// is only relabelled. changed, if given, receives every vertex whose sample or distance
/// changed (possibly twice); new_rank, if given, each old sample's new rank (-1: removed).
void flood_update(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& old_samples,
                  const std::vector<int32_t>& samples, Clustering& clustering, std::vector<int32_t>* changed = nullptr,
                  std::vector<int32_t>* new_rank = nullptr);

}  // namespace topstoc
