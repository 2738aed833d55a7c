#include "topology/loop_shortening.hpp"

#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <queue>
#include <tuple>

namespace topstoc {

LoopTightener::LoopTightener(const ClosedSurface& s, const std::vector<double>& weight, const SurfaceHomology* homology)
    : surface_(s),
      weight_(weight),
      homology_(homology),
      paths_(s, weight),
      vertex_stamp_(s.num_vertices(), 0),
      face_stamp_(s.num_faces(), 0),
      edge_stamp_(s.num_edges(), 0),
      ring_stamp_(s.num_vertices(), 0),
      vertex_faces_(s.num_vertices(), 0),
      edge_faces_(s.num_edges(), 0),
      ring_(s.num_vertices(), 0),
      source_(s.num_vertices(), 0),
      on_loop_(s.num_vertices(), -1) {
  if (homology_) {
    // Class hashes: a fixed random linear form of the integer homology coordinates.
    uint64_t state = 0x9e3779b97f4a7c15ull;
    for (int32_t j = 0; j < homology_->dimension(); ++j) {
      state += 0x9e3779b97f4a7c15ull;
      uint64_t z = state;
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
      coefficient_.push_back(z ^ (z >> 31));
    }
    hash_.resize(s.num_vertices());
  }
}

uint64_t LoopTightener::edge_hash(int32_t e, bool forward) const {
  uint64_t h = 0;
  homology_->for_each_crossing(e, [&](int32_t j, int sign) {
    h += (forward == (sign > 0) ? coefficient_[j] : uint64_t(0) - coefficient_[j]);
  });
  return h;
}

void LoopTightener::grow_disk(const std::vector<int32_t>& around, int32_t seed, int32_t rings, int32_t max_region,
                              bool along) {
  const ClosedSurface& s = surface_;
  ++stamp_;
  disk_vertices_.clear();
  // Vertices within `rings` hops of `around` may carry disk faces; each remembers which vertex
  // of `around` it is closest to.
  queue_.clear();
  for (size_t i = 0; i < around.size(); ++i) {
    const int32_t v = around[i];
    if (ring_stamp_[v] != stamp_) {
      ring_stamp_[v] = stamp_;
      ring_[v] = 0;
      source_[v] = int32_t(i);
      queue_.push_back(v);
    }
  }
  for (size_t head = 0; head < queue_.size(); ++head) {
    const int32_t v = queue_[head];
    if (ring_[v] == rings) continue;
    for (int32_t i = s.adjacency_offsets[v]; i < s.adjacency_offsets[v + 1]; ++i) {
      const int32_t u = s.adjacency[i];
      if (ring_stamp_[u] == stamp_) continue;
      ring_stamp_[u] = stamp_;
      ring_[u] = ring_[v] + 1;
      source_[u] = source_[v];
      queue_.push_back(u);
    }
  }
  auto count = [&](std::vector<uint32_t>& stamp, std::vector<int32_t>& faces, int32_t x) {
    return stamp[x] == stamp_ ? faces[x] : 0;
  };
  auto bump = [&](std::vector<uint32_t>& stamp, std::vector<int32_t>& faces, int32_t x) {
    if (stamp[x] != stamp_) {
      stamp[x] = stamp_;
      faces[x] = 0;
    }
    ++faces[x];
  };
  auto bump_vertex = [&](int32_t v) {
    if (vertex_stamp_[v] != stamp_) disk_vertices_.push_back(v);
    bump(vertex_stamp_, vertex_faces_, v);
  };
  // A face may join when it meets the disk along exactly one edge and brings a new vertex, or
  // along exactly two edges: either way the disk stays a disk.
  auto can_join = [&](int32_t f) {
    if (face_stamp_[f] == stamp_) return false;
    const int32_t* t = &s.triangles[3 * size_t(f)];
    for (int c = 0; c < 3; ++c)
      if (ring_stamp_[t[c]] != stamp_) return false;
    int32_t shared = 0, opposite = -1;
    for (int c = 0; c < 3; ++c)
      if (count(edge_stamp_, edge_faces_, s.face_edges[3 * size_t(f) + c]) > 0) {
        ++shared;
        opposite = t[(c + 2) % 3];  // the corner off the shared edge c
      }
    if (shared == 2) return true;
    return shared == 1 && count(vertex_stamp_, vertex_faces_, opposite) == 0;
  };
  auto join = [&](int32_t f) {
    face_stamp_[f] = stamp_;
    for (int c = 0; c < 3; ++c) {
      bump_vertex(s.triangles[3 * size_t(f) + c]);
      bump(edge_stamp_, edge_faces_, s.face_edges[3 * size_t(f) + c]);
    }
  };
  auto across = [&](int32_t f, int c) {
    const int32_t e = s.face_edges[3 * size_t(f) + c];
    return s.edge_faces[2 * size_t(e)] == f ? s.edge_faces[2 * size_t(e) + 1] : s.edge_faces[2 * size_t(e)];
  };
  join(seed);
  int32_t size = 1;
  if (!along) {  // breadth first from the seed
    queue_.assign(1, seed);
    for (size_t head = 0; head < queue_.size() && size < max_region; ++head)
      for (int c = 0; c < 3; ++c) {
        const int32_t g = across(queue_[head], c);
        if (can_join(g)) {
          join(g);
          ++size;
          queue_.push_back(g);
        }
      }
    return;
  }
  // Along `around` in its order: the disk follows the loop and meets itself only where the
  // loop closes, so the cut it leaves there crosses the band once.
  using Key = std::tuple<int32_t, int32_t, int32_t>;  // (farthest source along the loop, ring, face)
  std::priority_queue<Key, std::vector<Key>, std::greater<Key>> heap;
  auto push_neighbours = [&](int32_t f) {
    for (int c = 0; c < 3; ++c) {
      const int32_t g = across(f, c);
      if (face_stamp_[g] == stamp_) continue;
      const int32_t* t = &s.triangles[3 * size_t(g)];
      if (ring_stamp_[t[0]] != stamp_ || ring_stamp_[t[1]] != stamp_ || ring_stamp_[t[2]] != stamp_) continue;
      heap.emplace(std::max({source_[t[0]], source_[t[1]], source_[t[2]]}),
                   std::max({ring_[t[0]], ring_[t[1]], ring_[t[2]]}), g);
    }
  };
  push_neighbours(seed);
  while (!heap.empty() && size < max_region) {
    const int32_t g = std::get<2>(heap.top());
    heap.pop();
    if (!can_join(g)) continue;  // pushed again if a neighbour joins later
    join(g);
    ++size;
    push_neighbours(g);
  }
}

bool LoopTightener::improve_window(std::vector<int32_t>& loop, size_t start, int32_t w, const TightenParams& params) {
  const ClosedSurface& s = surface_;
  const size_t n = loop.size();
  std::vector<int32_t> window(size_t(w) + 1);
  double old_length = 0.0;
  for (int32_t i = 0; i <= w; ++i) window[i] = loop[(start + i) % n];
  for (int32_t i = 0; i < w; ++i) old_length += weight_[s.find_edge(window[i], window[i + 1])];
  // A shorter path between the ends stays within half the window's length of it.
  grow_disk(window, s.edge_faces[2 * size_t(s.find_edge(window[0], window[1]))], w / 2 + 2, params.max_region, false);
  auto in_disk = [&](int32_t v) { return vertex_stamp_[v] == stamp_ && vertex_faces_[v] > 0; };
  auto edge_in_disk = [&](int32_t e) { return edge_stamp_[e] == stamp_ && edge_faces_[e] > 0; };
  for (int32_t i = 0; i < w; ++i)
    if (!edge_in_disk(s.find_edge(window[i], window[i + 1]))) return false;  // the window leaves the disk
  // The new path may use the window's own vertices but no other vertex of the loop.
  auto allowed = [&](int32_t v) {
    if (!in_disk(v)) return false;
    const int32_t p = on_loop_[v];
    return p < 0 || size_t((p - int64_t(start) + int64_t(n)) % int64_t(n)) <= size_t(w);
  };
  const int32_t a = window.front(), b = window.back();
  paths_.run({a}, allowed, edge_in_disk, b);
  if (!paths_.reached(b) || !(paths_.distance(b) < old_length * (1.0 - 1e-12))) return false;
  std::vector<int32_t> replaced = paths_.path_to(b);  // a ... b
  for (size_t i = size_t(w) + 1; i < n; ++i) replaced.push_back(loop[(start + i) % n]);
  for (int32_t v : loop) on_loop_[v] = -1;
  loop = std::move(replaced);
  for (size_t i = 0; i < loop.size(); ++i) on_loop_[loop[i]] = int32_t(i);
  return true;
}

bool LoopTightener::improve_band(std::vector<int32_t>& loop, int32_t rings, const TightenParams& params) {
  const ClosedSurface& s = surface_;
  const size_t n = loop.size();
  double old_length = 0.0;
  uint64_t loop_hash = 0;
  for (size_t i = 0; i < n; ++i) {
    const int32_t e = s.find_edge(loop[i], loop[(i + 1) % n]);
    old_length += weight_[e];
    loop_hash += edge_hash(e, s.edge_vertices[2 * size_t(e)] == loop[i]);
  }
  grow_disk(loop, s.edge_faces[2 * size_t(s.find_edge(loop[0], loop[1]))], rings, 4 * params.max_region, true);
  auto in_disk = [&](int32_t v) { return vertex_stamp_[v] == stamp_ && vertex_faces_[v] > 0; };
  auto edge_in_disk = [&](int32_t e) { return edge_stamp_[e] == stamp_ && edge_faces_[e] > 0; };
  // Class hash of the tree path from the root to every disk vertex. In a disk every path between
  // two vertices has the same class, so a chord's cycle has a class known without a search.
  const int32_t root = disk_vertices_.front();
  queue_.assign(1, root);
  hash_[root] = 0;
  ++tree_stamp_;
  if (tree_seen_.size() != size_t(s.num_vertices())) tree_seen_.assign(s.num_vertices(), 0);
  tree_seen_[root] = tree_stamp_;
  for (size_t head = 0; head < queue_.size(); ++head) {
    const int32_t v = queue_[head];
    for (int32_t i = s.adjacency_offsets[v]; i < s.adjacency_offsets[v + 1]; ++i) {
      const int32_t u = s.adjacency[i], e = s.adjacency_edge[i];
      if (tree_seen_[u] == tree_stamp_ || !edge_in_disk(e)) continue;
      tree_seen_[u] = tree_stamp_;
      hash_[u] = hash_[v] + edge_hash(e, s.edge_vertices[2 * size_t(e)] == v);
      queue_.push_back(u);
    }
  }
  // Chords in the loop's class (either direction), then the shortest cycle through each.
  double best = old_length * (1.0 - 1e-12);
  std::vector<int32_t> best_cycle;
  bool best_reversed = false;
  for (int32_t x : disk_vertices_) {
    for (int32_t i = s.adjacency_offsets[x]; i < s.adjacency_offsets[x + 1]; ++i) {
      const int32_t y = s.adjacency[i], e = s.adjacency_edge[i];
      if (!in_disk(y) || edge_in_disk(e) || ring_stamp_[y] != stamp_) continue;
      const uint64_t h = hash_[x] + edge_hash(e, s.edge_vertices[2 * size_t(e)] == x) - hash_[y];
      if (h != loop_hash && h != uint64_t(0) - loop_hash) continue;
      if (weight_[e] >= best) continue;
      paths_.run({y}, in_disk, edge_in_disk, x, best - weight_[e]);
      if (!paths_.reached(x) || paths_.distance(x) + weight_[e] >= best) continue;
      best = paths_.distance(x) + weight_[e];
      best_cycle = paths_.path_to(x);  // y ... x, closed by the chord x -> y
      best_reversed = h != loop_hash;
    }
  }
  if (best_cycle.empty()) return false;
  if (best_reversed) std::reverse(best_cycle.begin(), best_cycle.end());
  // The hash only found it: the integer class must match exactly.
  if (homology_->integer_class_of_loop(s, best_cycle) != homology_->integer_class_of_loop(s, loop)) return false;
  for (int32_t v : loop) on_loop_[v] = -1;
  loop = std::move(best_cycle);
  for (size_t i = 0; i < loop.size(); ++i) on_loop_[loop[i]] = int32_t(i);
  return true;
}

std::vector<int32_t> LoopTightener::tighten(std::vector<int32_t> loop, const TightenParams& params, Progress* progress) {
  for (size_t i = 0; i < loop.size(); ++i) on_loop_[loop[i]] = int32_t(i);
  for (int32_t round = 0; round < params.max_rounds; ++round) {
    // Band moves while they help: each finds the best loop of the class within a narrow band, so
    // a loop far from its best position walks there band by band (narrow bands cost least: the
    // work of a move grows with the square of its width).
    for (int32_t moves = 0; homology_ && loop.size() >= 4 && moves < 256; ++moves) {
      const int32_t rings = params.band_rings > 0 ? params.band_rings : 3;
      if (progress) progress->update(0.0);
      if (!improve_band(loop, rings, params)) break;
    }
    // Window moves, long windows first for big moves; short ones get out of the spots where a
    // disk grown around a long window wraps around a handle and blocks the shortcut.
    int32_t last = -1;
    bool windows_changed = false;
    for (int32_t size = params.max_window; size >= 4; size /= 2) {
      if (std::min<int32_t>(size, int32_t(loop.size() / 2)) == last) continue;
      last = std::min<int32_t>(size, int32_t(loop.size() / 2));
      size_t pos = 0, since_change = 0, improvements = 0;
      while (since_change < loop.size() && improvements < 4 * loop.size()) {
        const int32_t w = std::min<int32_t>(size, int32_t(loop.size() / 2));
        if (w < 2) break;
        const size_t step = std::max(1, w / 2);
        if (progress) progress->update(0.0);
        if (improve_window(loop, pos % loop.size(), w, params)) {
          windows_changed = true;
          ++improvements;
          pos = step;  // the loop now starts at the window's first vertex
          since_change = 0;
        } else {
          pos += step;
          since_change += step;
        }
      }
    }
    // Band moves are optimal within their band: window moves only matter when they found more.
    if (!windows_changed) break;
  }
  for (int32_t v : loop) on_loop_[v] = -1;
  return loop;
}

void tighten_loops(const ClosedSurface& surface, const std::vector<double>& edge_weight, const SurfaceHomology* homology,
                   std::vector<std::vector<int32_t>>& loops, const TightenParams& params, Progress* progress) {
  const int64_t n = int64_t(loops.size());
  std::atomic<int64_t> next{0};
  std::atomic<bool> stop{false};
  // Loops of very uneven cost: taken one at a time by whichever member is free.
  parallel_region(n >= 2 ? max_threads() : 1, [&](Team& team) {
    LoopTightener tightener(surface, edge_weight, homology);
    Progress* mine = team.index() == 0 ? progress : nullptr;
    try {
      team.for_dynamic(next, n, 1, [&](int64_t i) {
        if (!stop.load(std::memory_order_relaxed)) loops[size_t(i)] = tightener.tighten(std::move(loops[size_t(i)]), params, mine);
      });
    } catch (...) {
      stop = true;
      throw;
    }
  });
}

}  // namespace topstoc
