#include "topstoc/clustering.hpp"

#include <climits>
#include <stdexcept>
#include <string>

namespace topstoc {

namespace {

// Level-synchronous relaxation from `frontier` (all at distance `level`): a neighbour improves
// when (level + 1, rank) beats what it holds. Serves the full fill (everything starts
// unreached) and incremental additions (only improvements propagate) alike.
void relax_levels(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> frontier, int32_t level,
                  Clustering& c, std::vector<uint8_t>* cross_faces) {
  const auto& ao = mesh.adjacency_offsets();
  const auto& adj = mesh.adjacency();
  const auto& ae = mesh.adjacency_edge();
  const auto& efo = mesh.edge_face_offsets();
  const auto& ef = mesh.edge_faces();
  const auto& edge_feature = layout.edge_feature;
  const auto& vertex_feature = layout.vertex_feature;
  std::vector<int32_t>& dist = c.dist;
  std::vector<int32_t>& label = c.label;
  std::vector<int32_t>& parent = c.parent;
  std::vector<int32_t> next;
  std::vector<uint8_t> in_next(mesh.num_vertices(), 0);
  while (!frontier.empty()) {
    next.clear();
    const int32_t d = level + 1;
    for (int32_t v : frontier) {
      const int32_t lv = label[v];
      for (int32_t i = ao[v]; i < ao[v + 1]; ++i) {
        const int32_t u = adj[i];
        // Labels at distance <= level are final: an edge to another cluster's vertex is a
        // cluster border, found from its farther end once both ends are final.
        if (cross_faces && dist[u] <= level && label[u] != lv)
          for (int32_t j = efo[ae[i]]; j < efo[ae[i] + 1]; ++j) (*cross_faces)[ef[j]] = 1;
        // Feature vertices are entered only along feature edges.
        if (vertex_feature[u] && !edge_feature[ae[i]]) continue;
        // (distance, rank) in lexicographic order: a shorter distance wins, then the lower rank.
        if (d < dist[u] || (d == dist[u] && lv < label[u])) {
          dist[u] = d;
          label[u] = lv;
          parent[u] = v;
          if (!in_next[u]) {
            in_next[u] = 1;
            next.push_back(u);
          }
        }
      }
    }
    for (int32_t u : next) in_next[u] = 0;
    frontier.swap(next);
    ++level;
  }
}

void seed_and_relax(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                    int32_t first_new, Clustering& c, std::vector<uint8_t>* cross_faces) {
  const int32_t n = mesh.num_vertices();
  std::vector<int32_t> frontier;
  for (size_t r = size_t(first_new); r < samples.size(); ++r) {
    const int32_t s = samples[r];
    if (s < 0 || s >= n)
      throw std::invalid_argument("sample " + std::to_string(r) + " is vertex " + std::to_string(s) + ", outside [0, " +
                                  std::to_string(n) + ")");
    if (c.dist[s] == 0) throw std::invalid_argument("vertex " + std::to_string(s) + " is sampled twice");
    c.dist[s] = 0;
    c.label[s] = static_cast<int32_t>(r);
    c.parent[s] = -1;
    frontier.push_back(s);
  }
  relax_levels(mesh, layout, std::move(frontier), 0, c, cross_faces);
}

}  // namespace

void flood(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples, Clustering& out,
           std::vector<uint8_t>* cross_faces) {
  const int32_t n = mesh.num_vertices();
  out.label.assign(n, -1);
  out.dist.assign(n, INT_MAX);
  out.parent.assign(n, -1);
  if (cross_faces) cross_faces->assign(mesh.num_faces(), 0);
  seed_and_relax(mesh, layout, samples, 0, out, cross_faces);
}

void flood_add(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
               int32_t first_new, Clustering& c) {
  seed_and_relax(mesh, layout, samples, first_new, c, nullptr);
}

}  // namespace topstoc
