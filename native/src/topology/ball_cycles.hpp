// Which fundamental cycles of a shortest-path tree are independent in H1 of the shorter ones,
// by union-find on the faces instead of linear algebra on their classes.
//
// For a spanning tree T and a set S of edges outside it, the fundamental cycles of S are
// independent in H1 exactly when the faces stay connected across the edges in neither T nor S
// (Eppstein 2003; Erickson and Whittlesey 2005): Kruskal on the faces, the other edges first,
// then the candidates longest first, leaves out exactly the greedy basis of the candidates (the
// shortest-first picks that are independent of the shorter ones). A tree grown to a ball only
// spans the ball: every face with a vertex outside it counts as one face, which can only join
// more faces, so a candidate left out is always dependent on shorter ones of the same tree
// (some dependent ones may be kept; the caller's own basis sorts those out). The cost is the
// ball's size, whatever the genus.
#pragma once

#include <cstdint>
#include <vector>

#include "core/union_find.hpp"
#include "topology/closed_surface.hpp"
#include "topology/shortest_paths.hpp"

namespace topstoc {

class BallCycles {
 public:
  explicit BallCycles(const ClosedSurface& surface)
      : s_(surface), face_stamp_(surface.num_faces(), 0), face_id_(surface.num_faces(), 0),
        edge_stamp_(surface.num_edges(), 0), edge_mark_(surface.num_edges(), 0) {}

  /// Takes the ball of a new tree: every edge outside the tree between settled vertices is a
  /// cycle, and group[i] says which candidate list edge i's cycle belongs to (-1: none).
  void start(const ShortestPaths& tree, const std::vector<int32_t>& edges, const std::vector<int8_t>& group);

  /// The edges of `group` given to the last start(), shortest cycle first: keep[i] is set when
  /// candidate i's fundamental cycle may extend the basis of the shorter ones.
  void independent(int8_t group, const std::vector<int32_t>& candidates, std::vector<uint8_t>& keep);

 private:
  int32_t node(int32_t face) const { return face_stamp_[face] == stamp_ ? face_id_[face] : 0; }
  void join(UnionFind& sets, int32_t e) { sets.unite(node(s_.edge_faces[2 * size_t(e)]), node(s_.edge_faces[2 * size_t(e) + 1])); }

  const ClosedSurface& s_;
  uint32_t stamp_ = 0;
  std::vector<uint32_t> face_stamp_;
  std::vector<int32_t> face_id_;  // 0: outside the ball (one node); 1..: the ball's faces
  std::vector<uint32_t> edge_stamp_;
  std::vector<int8_t> edge_mark_;  // this ball's edges: kTree, or the candidate group
  std::vector<int32_t> grouped_;   // edges in some group
  UnionFind base_, sets_;          // faces joined across the edges in no group; a copy per group
};

}  // namespace topstoc
