// Fans around a vertex: the groups of its triangles that are connected across edges which are
// shared by exactly two triangles and not blocked. With no edge blocked this tells manifold
// vertices (one fan) from pinched ones; with feature edges blocked it gives the sectors that the
// decimation treats as separate sides of a border.
//
// Everything is read from the vertex's own faces (Mesh::for_each_face): the faces of an edge at
// v are v's faces holding its other end, so no table of the faces of every edge is needed.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc {

/// The faces around v in Mesh::for_each_face order (the slots), with each face's corner after v
/// (its side leaving v) and before v (its side arriving at v).
struct VertexStar {
  std::vector<int32_t> faces, next, prev;
  /// (other end, slot) for both sides of every slot, sorted: the faces of edge (v, w) are the
  /// slots of the run with w.
  std::vector<std::pair<int32_t, int32_t>> sides;

  void read(const Mesh& mesh, int32_t v) {
    faces.clear(), next.clear(), prev.clear(), sides.clear();
    mesh.for_each_face(v, [&](int32_t f) {
      const int32_t* t = &mesh.faces()[3 * size_t(f)];
      const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const int32_t slot = int32_t(faces.size());
      faces.push_back(f);
      next.push_back(t[(c + 1) % 3]);
      prev.push_back(t[(c + 2) % 3]);
      sides.push_back({t[(c + 1) % 3], slot});
      sides.push_back({t[(c + 2) % 3], slot});
    });
    std::sort(sides.begin(), sides.end());
  }
  int32_t size() const { return int32_t(faces.size()); }
  /// Calls fn(w, first, count) for each edge (v, w): its `count` faces are the slots of
  /// sides[first, first + count).
  template <class Fn>
  void for_each_edge(Fn&& fn) const {
    for (size_t a = 0; a < sides.size();) {
      size_t b = a + 1;
      while (b < sides.size() && sides[b].first == sides[a].first) ++b;
      fn(sides[a].first, int32_t(a), int32_t(b - a));
      a = b;
    }
  }
  /// How many of v's faces hold w: the face count of edge (v, w).
  int32_t edge_faces(int32_t w) const {
    const auto lo = std::lower_bound(sides.begin(), sides.end(), std::pair<int32_t, int32_t>{w, INT32_MIN});
    const auto hi = std::lower_bound(lo, sides.end(), std::pair<int32_t, int32_t>{w + 1, INT32_MIN});
    return int32_t(hi - lo);
  }
};

/// Groups the triangles around v into fans. fan_of_slot receives, for each slot of v (its faces
/// in Mesh::for_each_face order, as mesh.vertex_faces() lists them), the fan index (0, 1, ...)
/// in order of first appearance. blocked(e) says whether edge e separates fans even when it has
/// two triangles. Returns the number of fans. fans_of_star reads them from v's star as read.
template <class Blocked>
int32_t fans_of_star(const Mesh& mesh, int32_t v, const VertexStar& star, Blocked blocked,
                     std::vector<int32_t>& fan_of_slot) {
  const int32_t count = star.size();
  fan_of_slot.resize(count);
  // Union-find over the slots of v; valences are small, so the work stays in fixed buffers.
  std::array<int32_t, 64> small_parent;
  std::vector<int32_t> large_parent;
  int32_t* parent = small_parent.data();
  if (count > int32_t(small_parent.size())) {
    large_parent.resize(count);
    parent = large_parent.data();
  }
  for (int32_t i = 0; i < count; ++i) parent[i] = i;
  auto find = [&](int32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  // The two faces of an edge with exactly two at v.
  star.for_each_edge([&](int32_t w, int32_t first, int32_t faces) {
    if (faces != 2 || blocked(mesh.find_edge(v, w))) return;
    const int32_t x = find(star.sides[first].second), y = find(star.sides[first + 1].second);
    if (x != y) parent[x < y ? y : x] = x < y ? x : y;
  });
  // Roots are the lowest slot of each fan, so numbering roots in slot order numbers fans in
  // order of first appearance.
  int32_t fans = 0;
  for (int32_t i = 0; i < count; ++i) {
    const int32_t root = find(i);
    if (root == i) fan_of_slot[i] = fans++;
    else fan_of_slot[i] = fan_of_slot[root];
  }
  return fans;
}

/// fans_of_star with v's star read into `star` (scratch).
template <class Blocked>
int32_t vertex_fans(const Mesh& mesh, int32_t v, Blocked blocked, std::vector<int32_t>& fan_of_slot,
                    VertexStar& star) {
  star.read(mesh, v);
  return fans_of_star(mesh, v, star, blocked, fan_of_slot);
}

/// vertex_fans with a star of its own.
template <class Blocked>
int32_t vertex_fans(const Mesh& mesh, int32_t v, Blocked blocked, std::vector<int32_t>& fan_of_slot) {
  VertexStar star;
  return vertex_fans(mesh, v, blocked, fan_of_slot, star);
}

}  // namespace topstoc
