#include "topstoc/loop_shortening.hpp"

#include <algorithm>

namespace topstoc {

LoopTightener::LoopTightener(const Surface& s, const std::vector<double>& weight)
    : surface_(s),
      weight_(weight),
      paths_(s, weight),
      vertex_stamp_(s.num_vertices(), 0),
      face_stamp_(s.num_faces(), 0),
      edge_stamp_(s.num_edges(), 0),
      ring_stamp_(s.num_vertices(), 0),
      vertex_faces_(s.num_vertices(), 0),
      edge_faces_(s.num_edges(), 0),
      ring_(s.num_vertices(), 0),
      on_loop_(s.num_vertices(), -1) {}

void LoopTightener::grow_disk(const std::vector<int32_t>& window, int32_t rings, int32_t max_region) {
  const Surface& s = surface_;
  ++stamp_;
  // Vertices within `rings` hops of the window may carry disk faces.
  queue_.clear();
  for (int32_t v : window)
    if (ring_stamp_[v] != stamp_) {
      ring_stamp_[v] = stamp_;
      ring_[v] = 0;
      queue_.push_back(v);
    }
  for (size_t head = 0; head < queue_.size(); ++head) {
    const int32_t v = queue_[head];
    if (ring_[v] == rings) continue;
    for (int32_t i = s.adjacency_offsets[v]; i < s.adjacency_offsets[v + 1]; ++i) {
      const int32_t u = s.adjacency[i];
      if (ring_stamp_[u] == stamp_) continue;
      ring_stamp_[u] = stamp_;
      ring_[u] = ring_[v] + 1;
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
      bump(vertex_stamp_, vertex_faces_, s.triangles[3 * size_t(f) + c]);
      bump(edge_stamp_, edge_faces_, s.face_edges[3 * size_t(f) + c]);
    }
  };
  const int32_t seed_edge = s.find_edge(window[0], window[1]);
  const int32_t seed = s.edge_faces[2 * size_t(seed_edge)];
  join(seed);
  int32_t size = 1;
  queue_.assign(1, seed);
  for (size_t head = 0; head < queue_.size() && size < max_region; ++head) {
    const int32_t f = queue_[head];
    for (int c = 0; c < 3; ++c) {
      const int32_t e = s.face_edges[3 * size_t(f) + c];
      const int32_t g = s.edge_faces[2 * size_t(e)] == f ? s.edge_faces[2 * size_t(e) + 1] : s.edge_faces[2 * size_t(e)];
      if (can_join(g)) {
        join(g);
        ++size;
        queue_.push_back(g);
      }
    }
  }
}

bool LoopTightener::improve_window(std::vector<int32_t>& loop, size_t start, int32_t w, const TightenParams& params) {
  const Surface& s = surface_;
  const size_t n = loop.size();
  std::vector<int32_t> window(size_t(w) + 1);
  double old_length = 0.0;
  for (int32_t i = 0; i <= w; ++i) window[i] = loop[(start + i) % n];
  for (int32_t i = 0; i < w; ++i) old_length += weight_[s.find_edge(window[i], window[i + 1])];
  grow_disk(window, std::max(2, w / 3), params.max_region);
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

std::vector<int32_t> LoopTightener::tighten(std::vector<int32_t> loop, const TightenParams& params, Progress* progress) {
  for (size_t i = 0; i < loop.size(); ++i) on_loop_[loop[i]] = int32_t(i);
  for (int32_t round = 0; round < params.max_rounds; ++round) {
    bool changed = false;
    for (int32_t size : {params.max_window, std::max(2, params.max_window / 8)}) {
      size_t pos = 0, since_change = 0, improvements = 0;
      while (since_change < loop.size() && improvements < 4 * loop.size()) {
        const int32_t w = std::min<int32_t>(size, int32_t(loop.size() / 2));
        if (w < 2) break;
        const size_t step = std::max(1, w / 2);
        if (progress) progress->update(0.0);
        if (improve_window(loop, pos % loop.size(), w, params)) {
          changed = true;
          ++improvements;
          pos = step;  // the loop now starts at the window's first vertex
          since_change = 0;
        } else {
          pos += step;
          since_change += step;
        }
      }
    }
    if (!changed) break;
  }
  for (int32_t v : loop) on_loop_[v] = -1;
  return loop;
}

}  // namespace topstoc
