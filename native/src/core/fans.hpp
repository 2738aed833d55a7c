// Fans around a vertex: the groups of its triangles that are connected across edges which are
// shared by exactly two triangles and not blocked. With no edge blocked this tells manifold
// vertices (one fan) from pinched ones; with feature edges blocked it gives the sectors that the
// decimation treats as separate sides of a border.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc {

/// Groups the triangles around v into fans. fan_of_slot receives, for each slot of v in
/// mesh.vertex_faces(), the fan index (0, 1, ...) in order of first appearance.
/// blocked(e) says whether edge e separates fans even when it has two triangles.
/// Returns the number of fans.
template <class Blocked>
int32_t vertex_fans(const Mesh& mesh, int32_t v, Blocked blocked, std::vector<int32_t>& fan_of_slot) {
  const auto& vfo = mesh.vertex_face_offsets();
  const auto& vf = mesh.vertex_faces();
  const auto& faces = mesh.faces();
  const auto& fe = mesh.face_edges();
  const auto& efo = mesh.edge_face_offsets();
  const auto& ef = mesh.edge_faces();
  const int32_t begin = vfo[v], count = vfo[v + 1] - vfo[v];
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
  auto slot_of_face = [&](int32_t f) {
    for (int32_t i = 0; i < count; ++i)
      if (vf[begin + i] == f) return i;
    return -1;
  };
  for (int32_t i = 0; i < count; ++i) {
    const int32_t f = vf[begin + i];
    const int32_t* t = &faces[3 * size_t(f)];
    const int c = t[0] == v ? 0 : t[1] == v ? 1 : 2;
    // The two sides of f at v: leaving v (c -> c+1) and arriving at v (c+2 -> c).
    for (int side : {c, (c + 2) % 3}) {
      const int32_t e = fe[3 * size_t(f) + side];
      if (efo[e + 1] - efo[e] != 2 || blocked(e)) continue;
      const int32_t g = ef[efo[e]] == f ? ef[efo[e] + 1] : ef[efo[e]];
      if (g < f) continue;  // each pair once, from its lower face
      const int32_t j = slot_of_face(g);
      if (j < 0) continue;
      const int32_t a = find(i), b = find(j);
      if (a != b) parent[a < b ? b : a] = a < b ? a : b;
    }
  }
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

}  // namespace topstoc
