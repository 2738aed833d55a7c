#include "topology/loop_mapping.hpp"

#include <cmath>
#include <stdexcept>

namespace topstoc {

ClusterMap::ClusterMap(const ClosedSurface& full, const std::vector<double>& edge_weight, std::vector<int32_t> cluster_of,
                       std::vector<int32_t> representative)
    : full_(full), paths_(full, edge_weight), cluster_of_(std::move(cluster_of)), representative_(std::move(representative)) {
  const int32_t clusters = int32_t(representative_.size());
  member_offsets_.assign(size_t(clusters) + 1, 0);
  for (int32_t c : cluster_of_) {
    if (c < 0 || c >= clusters) throw std::logic_error("a vertex belongs to no coarse cluster");
    ++member_offsets_[c + 1];
  }
  for (int32_t c = 0; c < clusters; ++c) member_offsets_[c + 1] += member_offsets_[c];
  members_.resize(cluster_of_.size());
  std::vector<int32_t> fill(member_offsets_.begin(), member_offsets_.end() - 1);
  for (int32_t v = 0; v < int32_t(cluster_of_.size()); ++v) members_[fill[cluster_of_[v]]++] = v;
}

std::pair<int32_t, int32_t> ClusterMap::crossing_edge(int32_t a, int32_t b) const {
  const double* pa = full_.position(representative_[a]);
  const double* pb = full_.position(representative_[b]);
  auto distance = [](const double* p, const double* q) {
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
  };
  std::pair<int32_t, int32_t> best{-1, -1};
  double best_cost = INFINITY;
  for (int32_t i = member_offsets_[a]; i < member_offsets_[a + 1]; ++i) {
    const int32_t u = members_[i];
    for (int32_t j = full_.adjacency_offsets[u]; j < full_.adjacency_offsets[u + 1]; ++j) {
      const int32_t w = full_.adjacency[j];
      if (cluster_of_[w] != b) continue;
      // Detour of the path representative a -> u -> w -> representative b.
      const double cost = distance(pa, full_.position(u)) + distance(full_.position(u), full_.position(w)) +
                          distance(full_.position(w), pb);
      if (cost < best_cost) {
        best_cost = cost;
        best = {u, w};
      }
    }
  }
  return best;
}

std::vector<int32_t> ClusterMap::map_loop(const std::vector<int32_t>& coarse) {
  const size_t m = coarse.size();
  std::vector<std::pair<int32_t, int32_t>> crossings(m);
  for (size_t i = 0; i < m; ++i) {
    crossings[i] = crossing_edge(coarse[i], coarse[(i + 1) % m]);
    if (crossings[i].first < 0)
      throw std::logic_error("clusters " + std::to_string(coarse[i]) + " and " + std::to_string(coarse[(i + 1) % m]) +
                             " of the coarse loop do not touch");
  }
  std::vector<int32_t> loop;
  for (size_t i = 0; i < m; ++i) {
    // Inside cluster i: from where the loop enters (previous crossing) to where it leaves.
    const int32_t cluster = coarse[i];
    const int32_t entry = crossings[(i + m - 1) % m].second, exit = crossings[i].first;
    paths_.run({entry}, [&](int32_t v) { return cluster_of_[v] == cluster; }, exit);
    if (!paths_.reached(exit)) throw std::logic_error("coarse cluster " + std::to_string(cluster) + " is not connected");
    const auto path = paths_.path_to(exit);
    loop.insert(loop.end(), path.begin(), path.end());
  }
  return loop;
}

}  // namespace topstoc
