// Dijkstra on the edge graph of a ClosedSurface, restricted to an allowed set of vertices, with
// scratch arrays that are reset lazily (a run costs what it visits, not the surface's size).
// Used to pick, map and tighten loops.
#pragma once

#include <cstdint>
#include <limits>
#include <queue>
#include <vector>

#include "topology/closed_surface.hpp"

namespace topstoc {

class ShortestPaths {
 public:
  /// edge_weight: one non-negative weight per surface edge (length, or 1 to count edges).
  ShortestPaths(const ClosedSurface& surface, const std::vector<double>& edge_weight)
      : surface_(surface), weight_(edge_weight), stamp_(surface.num_vertices(), 0), distance_(surface.num_vertices()),
        parent_edge_(surface.num_vertices()), settled_flag_(surface.num_vertices(), 0) {}

  /// Shortest paths from `sources` (distance 0). Only vertices with allowed(v) are entered;
  /// the run stops once `target` is settled (-1: when everything reachable is).
  template <class Allowed>
  void run(const std::vector<int32_t>& sources, Allowed allowed, int32_t target = -1) {
    run(sources, allowed, [](int32_t) { return true; }, target);
  }

  /// Same, also skipping edges with !allowed_edge(e), and stopping at distance `limit`.
  template <class Allowed, class AllowedEdge>
  void run(const std::vector<int32_t>& sources, Allowed allowed, AllowedEdge allowed_edge, int32_t target,
           double limit = kInfinity) {
    ++run_;
    settled_.clear();
    using Item = std::pair<double, int32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    for (int32_t s : sources) {
      touch(s);
      distance_[s] = 0.0;
      heap.emplace(0.0, s);
    }
    while (!heap.empty()) {
      const auto [d, v] = heap.top();
      heap.pop();
      if (settled_flag_[v] == run_ || d > distance_[v]) continue;
      if (d > limit) return;
      settled_flag_[v] = run_;
      settled_.push_back(v);
      if (v == target) return;
      for (int32_t i = surface_.adjacency_offsets[v]; i < surface_.adjacency_offsets[v + 1]; ++i) {
        const int32_t u = surface_.adjacency[i];
        if (settled_flag_[u] == run_ || !allowed(u) || !allowed_edge(surface_.adjacency_edge[i])) continue;
        const double nd = d + weight_[surface_.adjacency_edge[i]];
        touch(u);
        if (nd < distance_[u]) {
          distance_[u] = nd;
          parent_edge_[u] = surface_.adjacency_edge[i];
          heap.emplace(nd, u);
        }
      }
    }
  }

  bool reached(int32_t v) const { return stamp_[v] == run_ && distance_[v] < kInfinity; }
  double distance(int32_t v) const { return stamp_[v] == run_ ? distance_[v] : kInfinity; }
  /// Edge through which v was reached (-1 for sources).
  int32_t parent_edge(int32_t v) const { return parent_edge_[v]; }
  int32_t parent(int32_t v) const {
    const int32_t e = parent_edge_[v];
    if (e < 0) return -1;
    const int32_t a = surface_.edge_vertices[2 * size_t(e)];
    return a == v ? surface_.edge_vertices[2 * size_t(e) + 1] : a;
  }
  /// Vertices from v's source to v.
  std::vector<int32_t> path_to(int32_t v) const {
    std::vector<int32_t> path;
    for (; v >= 0; v = parent(v)) path.push_back(v);
    return {path.rbegin(), path.rend()};
  }
  /// Settled vertices, in order of distance.
  const std::vector<int32_t>& settled() const { return settled_; }
  /// Whether the last run settled v (its distance and parent are final).
  bool is_settled(int32_t v) const { return settled_flag_[v] == run_; }

  static constexpr double kInfinity = std::numeric_limits<double>::infinity();

 private:
  void touch(int32_t v) {
    if (stamp_[v] != run_) {
      stamp_[v] = run_;
      distance_[v] = kInfinity;
      parent_edge_[v] = -1;
    }
  }

  const ClosedSurface& surface_;
  const std::vector<double>& weight_;
  uint32_t run_ = 0;
  std::vector<uint32_t> stamp_;
  std::vector<double> distance_;
  std::vector<int32_t> parent_edge_;
  std::vector<uint32_t> settled_flag_;
  std::vector<int32_t> settled_;
};

}  // namespace topstoc
