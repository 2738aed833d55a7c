#include "topology/homology.hpp"

#include <stdexcept>

#include "core/portable.hpp"

namespace topstoc {

int32_t Z2Vector::top() const {
  for (size_t k = words.size(); k-- > 0;)
    if (words[k]) return int32_t(64 * k + size_t(highest_bit(words[k])));
  return -1;
}

Z2Vector Z2Basis::reduce(Z2Vector x) const {
  Z2Vector unused(size_);
  return reduce(std::move(x), unused);
}

Z2Vector Z2Basis::reduce(Z2Vector x, Z2Vector& used) const {
  used = Z2Vector(size_);
  for (int32_t t = x.top(); t >= 0 && pivot_[t] >= 0; t = x.top()) {
    x.add(rows_[pivot_[t]]);
    used.add(combos_[pivot_[t]]);
  }
  return x;
}

bool Z2Basis::insert(const Z2Vector& x) {
  Z2Vector used;
  Z2Vector r = reduce(x, used);
  const int32_t t = r.top();
  if (t < 0) return false;
  used.flip(int32_t(sources_.size()));
  pivot_[t] = int32_t(rows_.size());
  rows_.push_back(std::move(r));
  combos_.push_back(std::move(used));
  sources_.push_back(x);
  return true;
}

SurfaceHomology::SurfaceHomology(const ClosedSurface& s) {
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
  // Orient the faces consistently (the surface is orientable): the left face of an edge is the
  // one that runs along it from its lower to its higher vertex.
  std::vector<int8_t> flip(nf, -1);
  queue.clear();
  if (nf) {
    flip[0] = 0;
    queue.push_back(0);
  }
  auto runs_forward = [&](int32_t f, int32_t e) {  // face f, as stored, runs along e low -> high
    for (int c = 0; c < 3; ++c)
      if (s.face_edges[3 * size_t(f) + c] == e) return s.triangles[3 * size_t(f) + c] == s.edge_vertices[2 * size_t(e)];
    return false;
  };
  for (size_t head = 0; head < queue.size(); ++head) {
    const int32_t f = queue[head];
    for (int c = 0; c < 3; ++c) {
      const int32_t e = s.face_edges[3 * size_t(f) + c];
      const int32_t g = s.edge_faces[2 * size_t(e)] == f ? s.edge_faces[2 * size_t(e) + 1] : s.edge_faces[2 * size_t(e)];
      if (flip[g] >= 0) continue;
      flip[g] = int8_t(flip[f] ^ (runs_forward(f, e) == runs_forward(g, e)));
      queue.push_back(g);
    }
  }
  auto left_face = [&](int32_t e) {
    const int32_t f = s.edge_faces[2 * size_t(e)];
    return (runs_forward(f, e) != bool(flip[f])) ? f : s.edge_faces[2 * size_t(e) + 1];
  };
  // Dual loop of each generator: across the generator, then back through the cotree. Each step
  // from face a across edge e counts +1 when a is e's left face.
  struct Crossing {
    int32_t edge, loop;
    int8_t sign;
  };
  std::vector<Crossing> crossings;
  auto face_across = [&](int32_t f, int32_t e) {
    return s.edge_faces[2 * size_t(e)] == f ? s.edge_faces[2 * size_t(e) + 1] : s.edge_faces[2 * size_t(e)];
  };
  auto step = [&](int32_t from, int32_t e, int32_t j) {
    crossings.push_back({e, j, int8_t(left_face(e) == from ? 1 : -1)});
  };
  std::vector<int32_t> down;
  for (int32_t j = 0; j < dimension(); ++j) {
    const int32_t e = generators_[j];
    const int32_t p = s.edge_faces[2 * size_t(e)], q = s.edge_faces[2 * size_t(e) + 1];
    step(p, e, j);
    // Up from q and from p to their lowest common ancestor; the part from p is walked downwards.
    int32_t a = q, b = p;
    down.clear();
    while (a != b) {
      if (depth[a] >= depth[b]) {
        step(a, parent_edge[a], j);
        a = face_across(a, parent_edge[a]);
      } else {
        down.push_back(b);
        b = face_across(b, parent_edge[b]);
      }
    }
    for (size_t i = down.size(); i-- > 0;) step(face_across(down[i], parent_edge[down[i]]), parent_edge[down[i]], j);
  }
  crossing_offsets_.assign(size_t(m) + 1, 0);
  for (const auto& c : crossings) ++crossing_offsets_[c.edge + 1];
  for (int32_t e = 0; e < m; ++e) crossing_offsets_[e + 1] += crossing_offsets_[e];
  crossing_.resize(crossings.size());
  crossing_sign_.resize(crossings.size());
  std::vector<int32_t> fill(crossing_offsets_.begin(), crossing_offsets_.end() - 1);
  for (const auto& c : crossings) {
    crossing_sign_[fill[c.edge]] = c.sign;
    crossing_[fill[c.edge]++] = c.loop;
  }
}

std::vector<int64_t> SurfaceHomology::integer_class_of_loop(const ClosedSurface& s, const std::vector<int32_t>& loop) const {
  std::vector<int64_t> x(dimension(), 0);
  for (size_t i = 0; i < loop.size(); ++i) {
    const int32_t a = loop[i], b = loop[(i + 1) % loop.size()];
    const int32_t e = s.find_edge(a, b);
    if (e < 0) throw std::logic_error("loop step " + std::to_string(i) + " is not an edge");
    add_edge_signed(x, e, s.edge_vertices[2 * size_t(e)] == a);
  }
  return x;
}

Z2Vector SurfaceHomology::class_of_edges(const std::vector<int32_t>& edges) const {
  Z2Vector x(dimension());
  for (int32_t e : edges) add_edge(x, e);
  return x;
}

Z2Vector SurfaceHomology::class_of_loop(const ClosedSurface& s, const std::vector<int32_t>& loop) const {
  Z2Vector x(dimension());
  for (size_t i = 0; i < loop.size(); ++i) {
    const int32_t e = s.find_edge(loop[i], loop[(i + 1) % loop.size()]);
    if (e < 0) throw std::logic_error("loop step " + std::to_string(i) + " is not an edge");
    add_edge(x, e);
  }
  return x;
}

bool SurfaceHomology::is_cycle(const ClosedSurface& s, const std::vector<int32_t>& edges) {
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
