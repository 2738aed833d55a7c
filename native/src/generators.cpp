#include "topstoc/generators.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "topstoc/union_find.hpp"

namespace topstoc {

std::vector<ComponentGenerators> compute_generators(const SimplicialComplex& k, const TopologyReport& report) {
  const int32_t n = k.num_vertices, num_edges = k.num_edges();
  std::vector<ComponentGenerators> out;
  std::vector<int32_t> slot(report.components.size(), -1);  // component -> index in out
  for (size_t c = 0; c < report.components.size(); ++c) {
    const auto& comp = report.components[c];
    if (comp.kind != ComponentKind::surface || comp.manifold != 1 || comp.closed != 1 || comp.orientable != 1) continue;
    slot[c] = static_cast<int32_t>(out.size());
    out.emplace_back();
    out.back().component = static_cast<int32_t>(c);
    out.back().genus = comp.genus;
    out.back().root = comp.first_vertex;
  }
  if (out.empty()) return out;
  auto selected = [&](int32_t v) { return slot[report.vertex_component[v]] >= 0; };

  // Breadth-first search tree T from each component's root.
  std::vector<int32_t> offsets, incident;
  vertex_edges(k, offsets, incident);
  std::vector<int32_t> depth(n, -1), parent_edge(n, -1), queue;
  std::vector<uint8_t> in_tree(num_edges, 0);
  int32_t max_depth = 0;
  for (const auto& g : out) {
    queue.assign(1, g.root);
    depth[g.root] = 0;
    for (size_t head = 0; head < queue.size(); ++head) {
      const int32_t v = queue[head];
      for (int32_t i = offsets[v]; i < offsets[v + 1]; ++i) {
        const int32_t e = incident[i];
        const int32_t u = k.edges[2 * size_t(e)] == v ? k.edges[2 * size_t(e) + 1] : k.edges[2 * size_t(e)];
        if (depth[u] >= 0) continue;
        depth[u] = depth[v] + 1;
        max_depth = std::max(max_depth, depth[u]);
        parent_edge[u] = e;
        in_tree[e] = 1;
        queue.push_back(u);
      }
    }
  }
  auto parent = [&](int32_t v) {
    const int32_t e = parent_edge[v];
    return k.edges[2 * size_t(e)] == v ? k.edges[2 * size_t(e) + 1] : k.edges[2 * size_t(e)];
  };

  // The other edges, bucketed by the length of the loop they close through T (counting sort).
  // Each edge is represented by its first side (the one whose twin comes later).
  const int32_t num_sides = 3 * k.num_triangles();
  std::vector<int32_t> bucket_offsets(2 * size_t(max_depth) + 2, 0), by_length;
  auto loop_key = [&](int32_t e) { return depth[k.edges[2 * size_t(e)]] + depth[k.edges[2 * size_t(e) + 1]]; };
  auto non_tree_side = [&](int32_t s) {
    const int32_t code = k.side_twin[s];
    return code >= 0 && (code >> 1) > s && !in_tree[k.triangle_edges[s]] && selected(k.triangles[s]);
  };
  for (int32_t s = 0; s < num_sides; ++s)
    if (non_tree_side(s)) ++bucket_offsets[loop_key(k.triangle_edges[s]) + 1];
  for (size_t i = 1; i < bucket_offsets.size(); ++i) bucket_offsets[i] += bucket_offsets[i - 1];
  by_length.resize(bucket_offsets.back());
  {
    std::vector<int32_t> fill(bucket_offsets.begin(), bucket_offsets.end() - 1);
    for (int32_t s = 0; s < num_sides; ++s)
      if (non_tree_side(s)) by_length[fill[loop_key(k.triangle_edges[s])]++] = s;
  }

  // Cotree: triangles joined across those edges, longest loop first. What joins nothing is a
  // generator; collected longest first, so reversed below.
  UnionFind triangles(k.num_triangles());
  std::vector<std::vector<int32_t>> found(out.size());
  for (auto it = by_length.rbegin(); it != by_length.rend(); ++it) {
    const int32_t s = *it;
    if (!triangles.unite(s / 3, (k.side_twin[s] >> 1) / 3))
      found[slot[report.vertex_component[k.triangles[s]]]].push_back(k.triangle_edges[s]);
  }

  std::vector<uint8_t> reached(n, 0), in_cut(num_edges, 0);
  std::vector<int32_t> from_a, from_b;
  for (size_t i = 0; i < out.size(); ++i) {
    auto& g = out[i];
    std::reverse(found[i].begin(), found[i].end());
    if (int64_t(found[i].size()) != 2 * int64_t(g.genus))
      throw std::logic_error("generators: component " + std::to_string(g.component) + " of genus " +
                             std::to_string(g.genus) + " left " + std::to_string(found[i].size()) +
                             " unpaired edges");
    reached[g.root] = 1;
    for (int32_t e : found[i]) {
      const int32_t a = k.edges[2 * size_t(e)], b = k.edges[2 * size_t(e) + 1];
      g.edges.push_back(a);
      g.edges.push_back(b);
      in_cut[e] = 1;
      // Loop: a, b, up from b to the lowest common ancestor, down to a's parent.
      from_a.clear();
      from_b.clear();
      int32_t x = a, y = b;
      while (x != y) {
        if (depth[x] >= depth[y]) {
          from_a.push_back(x);
          x = parent(x);
        } else {
          from_b.push_back(y);
          y = parent(y);
        }
      }
      g.loop_vertices.push_back(a);
      g.loop_vertices.insert(g.loop_vertices.end(), from_b.begin(), from_b.end());
      if (x != a) g.loop_vertices.push_back(x);
      if (!from_a.empty()) g.loop_vertices.insert(g.loop_vertices.end(), from_a.rbegin(), from_a.rend() - 1);
      g.loop_offsets.push_back(static_cast<int32_t>(g.loop_vertices.size()));
      // Cut graph: the tree paths from both ends towards the root, until they meet earlier ones.
      for (int32_t w : {a, b})
        for (; !reached[w]; w = parent(w)) {
          reached[w] = 1;
          in_cut[parent_edge[w]] = 1;
        }
    }
    // The path from the root to the first branching carries no loop: strip it.
    if (!found[i].empty()) {
      int32_t r = g.root;
      while (true) {
        int32_t degree = 0, only = -1;
        for (int32_t j = offsets[r]; j < offsets[r + 1]; ++j)
          if (in_cut[incident[j]]) {
            ++degree;
            only = incident[j];
          }
        if (degree != 1 || !in_tree[only]) break;
        in_cut[only] = 0;
        r = k.edges[2 * size_t(only)] == r ? k.edges[2 * size_t(only) + 1] : k.edges[2 * size_t(only)];
      }
      g.root = r;
    }
  }
  for (int32_t e = 0; e < num_edges; ++e)
    if (in_cut[e]) {
      auto& g = out[slot[report.vertex_component[k.edges[2 * size_t(e)]]]];
      g.cut_edges.push_back(k.edges[2 * size_t(e)]);
      g.cut_edges.push_back(k.edges[2 * size_t(e) + 1]);
    }
  return out;
}

}  // namespace topstoc
