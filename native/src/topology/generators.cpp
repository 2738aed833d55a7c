#include "topstoc/topology/generators.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/union_find.hpp"

namespace topstoc {

namespace {

// Calls visit(cursor) once for every edge at v, going once around v's fan. Only for vertices
// of closed manifold components, where the fan is a full cycle.
template <class Visit>
void for_each_edge_around(const SimplicialComplex& k, int32_t v, Visit visit) {
  const int32_t first = k.vertex_side[v];
  FanCursor at{first, true};
  do {
    visit(at);
    at.turn();
    if (!at.cross(k)) break;  // cannot happen on a closed manifold; guards the loop
  } while (at.side != first);
}

// Reorders a component's generators by the length of their loops, shortest first (stable).
void sort_by_loop_length(ComponentGenerators& g) {
  const size_t count = g.loop_offsets.size() - 1;
  std::vector<size_t> order(count);
  for (size_t i = 0; i < count; ++i) order[i] = i;
  auto length = [&](size_t i) { return g.loop_offsets[i + 1] - g.loop_offsets[i]; };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return length(a) < length(b); });
  std::vector<int32_t> edges, offsets = {0}, vertices;
  for (size_t i : order) {
    edges.push_back(g.edges[2 * i]);
    edges.push_back(g.edges[2 * i + 1]);
    vertices.insert(vertices.end(), g.loop_vertices.begin() + g.loop_offsets[i],
                    g.loop_vertices.begin() + g.loop_offsets[i + 1]);
    offsets.push_back(static_cast<int32_t>(vertices.size()));
  }
  g.edges.swap(edges);
  g.loop_offsets.swap(offsets);
  g.loop_vertices.swap(vertices);
}

// One run of compute_generators (tree-cotree): a breadth-first tree per closed orientable
// component, the cotree over the other edges, then the loops and the cut graph. The stages
// run in the order of run().
class GeneratorSearch {
 public:
  GeneratorSearch(const SimplicialComplex& k, const TopologyReport& report)
      : k(k), report(report), caller(k.vertex_source), n(k.num_vertices), num_sides(k.num_sides()) {}

  std::vector<ComponentGenerators> run() {
    pick_components();
    if (out.empty()) return std::move(out);
    grow_trees();
    join_cotree(edges_by_loop_length());
    reached.assign(n, 0);
    in_cut.assign(num_sides, 0);
    for (size_t i = 0; i < out.size(); ++i) trace_loops(i);
    list_cut_edges();
    return std::move(out);
  }

 private:
  const SimplicialComplex& k;
  const TopologyReport& report;
  const std::vector<int32_t>& caller;
  const int32_t n, num_sides;
  std::vector<ComponentGenerators> out;
  std::vector<int32_t> vertex_slot;  // per internal vertex: index in out, or -1
  std::vector<int32_t> depth, parent_side;
  std::vector<uint8_t> in_tree;
  int32_t max_depth = 0;
  std::vector<std::vector<int32_t>> found;  // per slot: generator sides
  std::vector<uint8_t> reached, in_cut;

  int32_t parent(int32_t v) const {
    const int32_t s = parent_side[v];
    return k.side_start(s) == v ? k.side_end(s) : k.side_start(s);
  }
  void mark_cut(int32_t s, uint8_t value) { in_cut[s] = in_cut[k.side_twin[s] >> 1] = value; }

  // The closed, orientable, manifold surface components, each a slot of the output.
  void pick_components() {
    std::vector<int32_t> slot(report.components.size(), -1);  // component -> index in out
    for (size_t c = 0; c < report.components.size(); ++c) {
      const auto& comp = report.components[c];
      if (comp.kind != ComponentKind::surface || comp.manifold != 1 || comp.closed != 1 || comp.orientable != 1) continue;
      slot[c] = static_cast<int32_t>(out.size());
      out.emplace_back();
      out.back().component = static_cast<int32_t>(c);
      out.back().genus = comp.genus;
      out.back().root = k.vertex_index[comp.first_vertex];  // internal until the end
    }
    if (out.empty()) return;
    vertex_slot.resize(n);
    for (int32_t v = 0; v < n; ++v) vertex_slot[v] = slot[report.vertex_component[caller[v]]];
  }

  // Breadth-first search tree T from each component's root. On a closed manifold the sides
  // starting at v (its star, contiguous) end at its neighbours, once each: cheaper to read than
  // walking the fan. parent_side[u] is a side on the tree edge from u's parent to u; in_tree
  // marks both sides of tree edges.
  void grow_trees() {
    depth.assign(n, -1);
    parent_side.assign(n, -1);
    in_tree.assign(num_sides, 0);
    std::vector<int32_t> queue;
    for (const auto& g : out) {
      queue.assign(1, g.root);
      depth[g.root] = 0;
      for (size_t head = 0; head < queue.size(); ++head) {
        const int32_t v = queue[head];
        for (int32_t i = k.vertex_star_offsets[v]; i < k.vertex_star_offsets[v + 1]; ++i) {
          const int32_t s = k.vertex_star[i];
          const int32_t u = k.side_end(s);
          if (depth[u] >= 0) continue;
          depth[u] = depth[v] + 1;
          max_depth = std::max(max_depth, depth[u]);
          parent_side[u] = s;
          in_tree[s] = 1;
          in_tree[k.side_twin[s] >> 1] = 1;
          queue.push_back(u);
        }
      }
    }
  }

  // The other edges (each by its lower side), bucketed by the length of the loop they close
  // through T (counting sort; ties by side).
  std::vector<int32_t> edges_by_loop_length() const {
    std::vector<int32_t> key(num_sides, -1);
    std::vector<int32_t> bucket_offsets(2 * size_t(max_depth) + 2, 0);
    for (int32_t s = 0; s < num_sides; ++s) {
      const int32_t code = k.side_twin[s];
      if (code < 0 || (code >> 1) < s || in_tree[s] || vertex_slot[k.side_start(s)] < 0) continue;
      key[s] = depth[k.side_start(s)] + depth[k.side_end(s)];
      ++bucket_offsets[key[s] + 1];
    }
    for (size_t i = 1; i < bucket_offsets.size(); ++i) bucket_offsets[i] += bucket_offsets[i - 1];
    std::vector<int32_t> by_length(bucket_offsets.back());
    for (int32_t s = 0; s < num_sides; ++s)
      if (key[s] >= 0) by_length[bucket_offsets[key[s]]++] = s;
    return by_length;
  }

  // Cotree: triangles joined across those edges, longest loop first. What joins nothing is a
  // generator; collected longest first (trace_loops reverses them).
  void join_cotree(const std::vector<int32_t>& by_length) {
    UnionFind triangles(k.num_triangles());
    found.assign(out.size(), {});
    for (auto it = by_length.rbegin(); it != by_length.rend(); ++it) {
      const int32_t s = *it;
      if (!triangles.unite(s / 3, (k.side_twin[s] >> 1) / 3)) found[vertex_slot[k.side_start(s)]].push_back(s);
    }
  }

  // Slot i's loops and its part of the cut graph (marked on sides, both sides of an edge).
  void trace_loops(size_t i) {
    auto& g = out[i];
    std::reverse(found[i].begin(), found[i].end());
    if (int64_t(found[i].size()) != 2 * int64_t(g.genus))
      throw std::logic_error("generators: component " + std::to_string(g.component) + " of genus " +
                             std::to_string(g.genus) + " left " + std::to_string(found[i].size()) +
                             " unpaired edges");
    reached[g.root] = 1;
    for (int32_t s : found[i]) trace_loop(g, s);
    if (!found[i].empty()) strip_root_path(g);
    g.root = caller[g.root];
    sort_by_loop_length(g);
  }

  // The loop of generator side s, and the cut graph's tree paths from its ends.
  void trace_loop(ComponentGenerators& g, int32_t s) {
    // Internal ids until the end; a is the end with the lower caller id.
    int32_t a = k.side_start(s), b = k.side_end(s);
    if (caller[a] > caller[b]) std::swap(a, b);
    g.edges.push_back(caller[a]);
    g.edges.push_back(caller[b]);
    mark_cut(s, 1);
    // Loop: a, b, up from b to the lowest common ancestor, down to a's parent.
    std::vector<int32_t> from_a, from_b;
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
    for (size_t j = g.loop_offsets.back(); j < g.loop_vertices.size(); ++j) g.loop_vertices[j] = caller[g.loop_vertices[j]];
    g.loop_offsets.push_back(static_cast<int32_t>(g.loop_vertices.size()));
    // Cut graph: the tree paths from both ends towards the root, until they meet earlier ones.
    for (int32_t w : {a, b})
      for (; !reached[w]; w = parent(w)) {
        reached[w] = 1;
        mark_cut(parent_side[w], 1);
      }
  }

  // The path from the root to the first branching carries no loop: strip it.
  void strip_root_path(ComponentGenerators& g) {
    int32_t r = g.root;
    while (true) {
      int32_t degree = 0, only = -1;
      for_each_edge_around(k, r, [&](const FanCursor& at) {
        if (in_cut[at.side]) {
          ++degree;
          only = at.side;
        }
      });
      if (degree != 1 || !in_tree[only]) break;
      const int32_t next = k.side_start(only) == r ? k.side_end(only) : k.side_start(only);
      mark_cut(only, 0);
      r = next;
    }
    g.root = r;
  }

  // Every cut edge once, in caller ids, sorted, to its component.
  void list_cut_edges() {
    std::vector<std::pair<int32_t, int32_t>> cut;
    for (int32_t s = 0; s < num_sides; ++s)
      if (in_cut[s] && (k.side_twin[s] >> 1) > s) {
        const int32_t a = caller[k.side_start(s)], b = caller[k.side_end(s)];
        cut.emplace_back(std::min(a, b), std::max(a, b));
      }
    std::sort(cut.begin(), cut.end());
    for (const auto& [a, b] : cut) {
      auto& g = out[vertex_slot[k.vertex_index[a]]];
      g.cut_edges.push_back(a);
      g.cut_edges.push_back(b);
    }
  }
};

}  // namespace

std::vector<ComponentGenerators> compute_generators(const SimplicialComplex& k, const TopologyReport& report) {
  return GeneratorSearch(k, report).run();
}

}  // namespace topstoc
