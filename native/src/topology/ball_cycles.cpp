#include "topology/ball_cycles.hpp"

namespace topstoc {

namespace {
constexpr int8_t kTree = -2;
}

void BallCycles::start(const ShortestPaths& tree, const std::vector<int32_t>& edges, const std::vector<int8_t>& group) {
  ++stamp_;
  for (int32_t v : tree.settled())
    if (tree.parent_edge(v) >= 0) {
      edge_stamp_[tree.parent_edge(v)] = stamp_;
      edge_mark_[tree.parent_edge(v)] = kTree;
    }
  grouped_.clear();
  for (size_t i = 0; i < edges.size(); ++i)
    if (group[i] >= 0) {
      edge_stamp_[edges[i]] = stamp_;
      edge_mark_[edges[i]] = group[i];
      grouped_.push_back(edges[i]);
    }
  // The ball's faces (all three corners settled) get ids from 1; the rest stay node 0.
  int32_t count = 1;
  for (int32_t a : tree.settled())
    for (int32_t i = 2 * s_.adjacency_offsets[a]; i < 2 * s_.adjacency_offsets[a + 1]; ++i) {
      const int32_t f = s_.edge_faces[2 * size_t(s_.adjacency_edge[i / 2]) + i % 2];
      if (face_stamp_[f] == stamp_) continue;
      const int32_t* t = &s_.triangles[3 * size_t(f)];
      if (!tree.is_settled(t[0]) || !tree.is_settled(t[1]) || !tree.is_settled(t[2])) continue;
      face_stamp_[f] = stamp_;
      face_id_[f] = count++;
    }
  base_.reset(count);
  // Join across every edge of the ball that is neither a tree edge nor in a group.
  for (int32_t a : tree.settled())
    for (int32_t i = s_.adjacency_offsets[a]; i < s_.adjacency_offsets[a + 1]; ++i) {
      const int32_t e = s_.adjacency_edge[i];
      if (s_.adjacency[i] < a && tree.is_settled(s_.adjacency[i])) continue;  // once per edge
      if (edge_stamp_[e] != stamp_) join(base_, e);
    }
}

void BallCycles::independent(int8_t group, const std::vector<int32_t>& candidates, std::vector<uint8_t>& keep) {
  sets_ = base_;
  for (int32_t e : grouped_)
    if (edge_mark_[e] != group) join(sets_, e);
  // Longest first: a candidate whose faces are already joined is in the greedy basis.
  keep.assign(candidates.size(), 0);
  for (size_t i = candidates.size(); i-- > 0;) {
    const int32_t e = candidates[i];
    keep[i] = !sets_.unite(node(s_.edge_faces[2 * size_t(e)]), node(s_.edge_faces[2 * size_t(e) + 1]));
  }
}

}  // namespace topstoc
