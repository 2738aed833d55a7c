#include "topstoc/homology.hpp"

#include <stdexcept>

namespace topstoc {

int32_t Bits::top() const {
  for (size_t k = words.size(); k-- > 0;)
    if (words[k]) return int32_t(64 * k + 63 - __builtin_clzll(words[k]));
  return -1;
}

Bits Z2Basis::reduce(Bits x) const {
  Bits unused(size_);
  return reduce(std::move(x), unused);
}

Bits Z2Basis::reduce(Bits x, Bits& used) const {
  used = Bits(size_);
  for (int32_t t = x.top(); t >= 0 && pivot_[t] >= 0; t = x.top()) {
    x.add(rows_[pivot_[t]]);
    used.add(combos_[pivot_[t]]);
  }
  return x;
}

bool Z2Basis::insert(const Bits& x) {
  Bits used;
  Bits r = reduce(x, used);
  const int32_t t = r.top();
  if (t < 0) return false;
  used.flip(int32_t(sources_.size()));
  pivot_[t] = int32_t(rows_.size());
  rows_.push_back(std::move(r));
  combos_.push_back(std::move(used));
  sources_.push_back(x);
  return true;
}

SurfaceHomology::SurfaceHomology(const Surface& s) {
  const int32_t n = s.num_vertices(), m = s.num_edges(), nf = s.num_faces();
  // Spanning tree of the vertices (breadth first: short tree paths).
  std::vector<uint8_t> in_tree(m, 0), seen(n, 0);
  std::vector<int32_t> queue;
  queue.reserve(n);
  if (n) {
    seen[0] = 1;
    queue.push_back(0);
  }
  for (size_t head = 0; head < queue.size(); ++head) {
    const int32_t v = queue[head];
    for (int32_t i = s.adjacency_offsets[v]; i < s.adjacency_offsets[v + 1]; ++i)
      if (!seen[s.adjacency[i]]) {
        seen[s.adjacency[i]] = 1;
        in_tree[s.adjacency_edge[i]] = 1;
        queue.push_back(s.adjacency[i]);
      }
  }
  // Spanning tree of the faces across the other edges, with parent edges and depths.
  std::vector<int32_t> parent_edge(nf, -1), depth(nf, -1);
  std::vector<uint8_t> in_cotree(m, 0);
  queue.clear();
  if (nf) {
    depth[0] = 0;
    queue.push_back(0);
  }
  for (size_t head = 0; head < queue.size(); ++head) {
    const int32_t f = queue[head];
    for (int c = 0; c < 3; ++c) {
      const int32_t e = s.face_edges[3 * size_t(f) + c];
      if (in_tree[e]) continue;
      const int32_t g = s.edge_faces[2 * size_t(e)] == f ? s.edge_faces[2 * size_t(e) + 1] : s.edge_faces[2 * size_t(e)];
      if (depth[g] >= 0) continue;
      depth[g] = depth[f] + 1;
      parent_edge[g] = e;
      in_cotree[e] = 1;
      queue.push_back(g);
    }
  }
  for (int32_t e = 0; e < m; ++e)
    if (!in_tree[e] && !in_cotree[e]) generators_.push_back(e);
  if (int64_t(generators_.size()) != 2 - s.euler())
    throw std::logic_error("tree-cotree left " + std::to_string(generators_.size()) + " edges, expected 2 - chi = " +
                           std::to_string(2 - s.euler()));
  // Dual loop of each generator: the cotree path between its two faces, plus the generator.
  std::vector<std::pair<int32_t, int32_t>> crossings;  // (edge, generator index)
  auto face_across = [&](int32_t f, int32_t e) {
    return s.edge_faces[2 * size_t(e)] == f ? s.edge_faces[2 * size_t(e) + 1] : s.edge_faces[2 * size_t(e)];
  };
  for (int32_t j = 0; j < dimension(); ++j) {
    const int32_t e = generators_[j];
    crossings.emplace_back(e, j);
    int32_t a = s.edge_faces[2 * size_t(e)], b = s.edge_faces[2 * size_t(e) + 1];
    while (a != b) {
      if (depth[a] < depth[b]) std::swap(a, b);
      crossings.emplace_back(parent_edge[a], j);
      a = face_across(a, parent_edge[a]);
    }
  }
  crossing_offsets_.assign(size_t(m) + 1, 0);
  for (const auto& c : crossings) ++crossing_offsets_[c.first + 1];
  for (int32_t e = 0; e < m; ++e) crossing_offsets_[e + 1] += crossing_offsets_[e];
  crossing_.resize(crossings.size());
  std::vector<int32_t> fill(crossing_offsets_.begin(), crossing_offsets_.end() - 1);
  for (const auto& c : crossings) crossing_[fill[c.first]++] = c.second;
}

Bits SurfaceHomology::class_of_edges(const std::vector<int32_t>& edges) const {
  Bits x(dimension());
  for (int32_t e : edges) add_edge(x, e);
  return x;
}

Bits SurfaceHomology::class_of_loop(const Surface& s, const std::vector<int32_t>& loop) const {
  Bits x(dimension());
  for (size_t i = 0; i < loop.size(); ++i) {
    const int32_t e = s.find_edge(loop[i], loop[(i + 1) % loop.size()]);
    if (e < 0) throw std::logic_error("loop step " + std::to_string(i) + " is not an edge");
    add_edge(x, e);
  }
  return x;
}

bool SurfaceHomology::is_cycle(const Surface& s, const std::vector<int32_t>& edges) {
  std::vector<uint8_t> parity(s.num_vertices(), 0);
  for (int32_t e : edges) {
    parity[s.edge_vertices[2 * size_t(e)]] ^= 1;
    parity[s.edge_vertices[2 * size_t(e) + 1]] ^= 1;
  }
  for (uint8_t p : parity)
    if (p) return false;
  return true;
}

}  // namespace topstoc
