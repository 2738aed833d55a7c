// Fans around a vertex: the groups of its triangles that are connected across edges which are
// shared by exactly two triangles and not blocked. With no edge blocked this tells manifold
// vertices (one fan) from pinched ones; with feature edges blocked it gives the sectors that the
// decimation treats as separate sides of a border.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/mesh.hpp"

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
  // Small union-find over the slots of v.
  fan_of_slot.assign(count, 0);
  std::vector<int32_t>& parent = fan_of_slot;
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
    for (int32_t c = 0; c < 3; ++c) {
      // The two sides of f that touch v: the side starting at v and the one ending at v.
      const bool touches = faces[3 * f + c] == v || faces[3 * f + (c + 1) % 3] == v;
      if (!touches) continue;
      const int32_t e = fe[3 * f + c];
      if (efo[e + 1] - efo[e] != 2 || blocked(e)) continue;
      const int32_t g = ef[efo[e]] == f ? ef[efo[e] + 1] : ef[efo[e]];
      const int32_t j = slot_of_face(g);
      if (j < 0) continue;
      const int32_t a = find(i), b = find(j);
      if (a != b) parent[a < b ? b : a] = a < b ? a : b;
    }
  }
  // Relabel roots to 0, 1, ... in order of first appearance.
  std::vector<int32_t> root(count);
  for (int32_t i = 0; i < count; ++i) root[i] = find(i);
  std::vector<int32_t> index(count, -1);
  int32_t fans = 0;
  for (int32_t i = 0; i < count; ++i) {
    if (index[root[i]] < 0) index[root[i]] = fans++;
    fan_of_slot[i] = index[root[i]];
  }
  return fans;
}

}  // namespace topstoc
