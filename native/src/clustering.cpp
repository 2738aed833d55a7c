#include "topstoc/clustering.hpp"

#include <climits>
#include <stdexcept>
#include <string>

namespace topstoc {

namespace {

// (distance, rank) packed so that one integer comparison orders them lexicographically.
inline uint64_t pack(int32_t dist, int32_t rank) { return (uint64_t(uint32_t(dist)) << 32) | uint32_t(rank); }
inline int32_t dist_of(uint64_t key) { return int32_t(key >> 32); }
inline int32_t rank_of(uint64_t key) { return int32_t(key & 0xffffffffu); }
constexpr uint64_t kUnreached = ~uint64_t(0);

// Level-synchronous relaxation from `frontier` (all at distance `level`): a neighbour improves
// when (level + 1, rank) beats what it holds. Serves the full fill (everything starts
// unreached) and incremental additions (only improvements propagate). With cross_edges, every
// edge between two clusters is recorded once, from its farther end, when both ends are final.
void relax_levels(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> frontier, int32_t level,
                  std::vector<uint64_t>& key, std::vector<int32_t>& parent, bool incremental,
                  std::vector<int32_t>* cross_edges) {
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  const auto& ae = mesh.adjacency_edge();
  const auto& edge_feature = layout.edge_feature;
  const auto& vertex_feature = layout.vertex_feature;
  std::vector<int32_t> next;
  // A full fill pushes a vertex only when it is first reached; an incremental one may lower the
  // rank of a vertex reached in an earlier fill, which must then be queued exactly once.
  std::vector<uint8_t> in_next(incremental ? mesh.num_vertices() : 0, 0);
  while (!frontier.empty()) {
    next.clear();
    const int32_t d = level + 1;
    for (int32_t v : frontier) {
      const int32_t rank = rank_of(key[v]);
      const uint64_t candidate = pack(d, rank);
      for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
        const int32_t u = adj[i];
        const uint64_t held = key[u];
        if (cross_edges && held != kUnreached && dist_of(held) <= level && rank_of(held) != rank &&
            (dist_of(held) < level || u > v))
          cross_edges->push_back(ae[i]);
        if (candidate >= held) continue;
        // Feature vertices are entered only along feature edges.
        if (vertex_feature[u] && !edge_feature[ae[i]]) continue;
        const bool first_reach = dist_of(held) > d || held == kUnreached;
        key[u] = candidate;
        parent[u] = v;
        if (incremental) {
          if (!in_next[u]) {
            in_next[u] = 1;
            next.push_back(u);
          }
        } else if (first_reach) {
          next.push_back(u);
        }
      }
    }
    if (incremental)
      for (int32_t u : next) in_next[u] = 0;
    frontier.swap(next);
    ++level;
  }
}

void seed_and_relax(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                    int32_t first_new, Clustering& c, std::vector<int32_t>* cross_edges) {
  const int32_t n = mesh.num_vertices();
  const bool incremental = first_new > 0;
  std::vector<uint64_t> key(n);
  for (int32_t v = 0; v < n; ++v) key[v] = c.label[v] < 0 ? kUnreached : pack(c.dist[v], c.label[v]);
  std::vector<int32_t> frontier;
  for (size_t r = size_t(first_new); r < samples.size(); ++r) {
    const int32_t s = samples[r];
    if (s < 0 || s >= n)
      throw std::invalid_argument("sample " + std::to_string(r) + " is vertex " + std::to_string(s) + ", outside [0, " +
                                  std::to_string(n) + ")");
    if (key[s] != kUnreached && dist_of(key[s]) == 0)
      throw std::invalid_argument("vertex " + std::to_string(s) + " is sampled twice");
    key[s] = pack(0, static_cast<int32_t>(r));
    c.parent[s] = -1;
    frontier.push_back(s);
  }
  relax_levels(mesh, layout, std::move(frontier), 0, key, c.parent, incremental, cross_edges);
  for (int32_t v = 0; v < n; ++v) {
    c.label[v] = key[v] == kUnreached ? -1 : rank_of(key[v]);
    c.dist[v] = key[v] == kUnreached ? INT_MAX : dist_of(key[v]);
  }
}

}  // namespace

void flood(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples, Clustering& out,
           std::vector<int32_t>* cross_edges) {
  const int32_t n = mesh.num_vertices();
  out.label.assign(n, -1);
  out.dist.assign(n, INT_MAX);
  out.parent.assign(n, -1);
  if (cross_edges) cross_edges->clear();
  seed_and_relax(mesh, layout, samples, 0, out, cross_edges);
}

void flood_add(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
               int32_t first_new, Clustering& c) {
  seed_and_relax(mesh, layout, samples, first_new, c, nullptr);
}

}  // namespace topstoc
