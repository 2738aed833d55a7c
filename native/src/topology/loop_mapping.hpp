// Loops found on a coarse version of a surface, carried back to the full surface (thesis
// 5.2.2).
//
// The coarse surface is a TopStoc decimation: each of its vertices stands for a cluster of
// full-surface vertices, and when every cluster is a disk, every two clusters meet in one arc
// and every three in at most one point (the closed ball property the decimation checks), the
// two surfaces are homeomorphic with clusters matching vertex stars. A coarse loop a0 a1 ...
// then becomes: for each coarse edge (ai, ai+1) a full edge between the two clusters, joined
// inside each cluster by a shortest path that stays in the cluster. The result is a simple
// closed loop (clusters are disjoint, each path is simple) in the class matching the coarse
// loop's (paths inside a disk, or inside two disks that share one arc, are all homotopic).
#pragma once

#include <cstdint>
#include <vector>

#include "topology/shortest_paths.hpp"
#include "topology/closed_surface.hpp"

namespace topstoc {

class ClusterMap {
 public:
  /// cluster_of: per full-surface vertex, its coarse vertex (0 .. num_clusters-1);
  /// representative: per coarse vertex, the full-surface vertex it was made from.
  ClusterMap(const ClosedSurface& full, const std::vector<double>& edge_weight, std::vector<int32_t> cluster_of,
             std::vector<int32_t> representative);

  /// The full-surface loop for a simple closed loop of coarse vertices. Throws
  /// std::logic_error when two consecutive clusters do not touch or a cluster is split.
  std::vector<int32_t> map_loop(const std::vector<int32_t>& coarse_loop);

  /// The full edge (two full vertices) standing for coarse edge (a, b): the crossing edge
  /// closest to the segment between the two representatives.
  std::pair<int32_t, int32_t> crossing_edge(int32_t a, int32_t b) const;

 private:
  const ClosedSurface& full_;
  ShortestPaths paths_;
  std::vector<int32_t> cluster_of_, representative_;
  std::vector<int32_t> member_offsets_, members_;  // full vertices of each cluster, CSR
};

}  // namespace topstoc
