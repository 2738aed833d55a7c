#include "decimate/deviation.hpp"

#include <algorithm>
#include <cmath>

namespace topstoc {

namespace {

std::vector<double> normalised(const Mesh& mesh, const Collapser& collapser) {
  std::vector<double> out(3 * size_t(mesh.num_vertices()));
  for (int32_t w = 0; w < mesh.num_vertices(); ++w) collapser.normalise(mesh.position(w), &out[3 * size_t(w)]);
  return out;
}

// Each input vertex, triangle centre and side middle to the collapsed surface, kept per
// first-pass vertex of the vertex (of each corner, for a centre; of the first end, for a side).
void from_input(const Mesh& mesh, const std::vector<double>& input, const std::vector<int32_t>& label,
                const TriangleBvh& surface, std::vector<double>& out2) {
  int32_t hint = -1;
  auto distance2 = [&](const double* point) {
    const ClosestHit hit = surface.closest(point, hint);
    hint = hit.slot;
    return hit.distance2;
  };
  for (int32_t w = 0; w < mesh.num_vertices(); ++w)
    if (label[w] >= 0) out2[label[w]] = std::max(out2[label[w]], distance2(&input[3 * size_t(w)]));
  const auto& faces = mesh.faces();
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* q = &faces[3 * size_t(f)];
    if (label[q[0]] < 0 || label[q[1]] < 0 || label[q[2]] < 0) continue;
    const double* p[3] = {&input[3 * size_t(q[0])], &input[3 * size_t(q[1])], &input[3 * size_t(q[2])]};
    double point[3];
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) point[i] = 0.5 * (p[j][i] + p[(j + 1) % 3][i]);
      out2[label[q[j]]] = std::max(out2[label[q[j]]], distance2(point));
    }
    for (int i = 0; i < 3; ++i) point[i] = (p[0][i] + p[1][i] + p[2][i]) / 3.0;
    const double centre2 = distance2(point);
    for (int j = 0; j < 3; ++j) out2[label[q[j]]] = std::max(out2[label[q[j]]], centre2);
  }
}

}  // namespace

InputSurface::InputSurface(const Mesh& mesh, const Collapser& collapser)
    : positions(normalised(mesh, collapser)), bvh(positions.data(), mesh.faces().data(), mesh.num_faces()) {}

Deviation surface_deviation(const Mesh& mesh, const InputSurface& input, const std::vector<int32_t>& label,
                          Collapser& collapser, const std::vector<int32_t>& triangles) {
  const int32_t n = collapser.vertices();
  std::vector<int32_t> survivor(n);
  for (int32_t v = 0; v < n; ++v) survivor[v] = collapser.survivor(v);
  Deviation out;
  for (int32_t v = 0; v < n; ++v) out.vertices += survivor[v] == v;
  std::vector<double> positions(3 * size_t(n));
  std::vector<int32_t> live;
  for (int32_t v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) positions[3 * size_t(v) + i] = collapser.position(v)[i];
  for (size_t t = 0; 3 * t < triangles.size(); ++t)
    if (collapser.face_alive(int32_t(t))) live.insert(live.end(), &triangles[3 * t], &triangles[3 * t] + 3);
  out.vertex2.assign(n, 0.0);
  out.faces = static_cast<int32_t>(live.size() / 3);
  if (out.faces == 0) return out;
  from_input(mesh, input.positions, label, TriangleBvh(positions.data(), live.data(), out.faces), out.vertex2);
  // Back to the input: each live triangle's centre, corners and side middles.
  std::vector<double> back2(n, 0.0);
  int32_t hint = -1;
  auto distance2 = [&](const double* point) {
    const ClosestHit hit = input.bvh.closest(point, hint);
    hint = hit.slot;
    return hit.distance2;
  };
  for (size_t t = 0; 3 * t < triangles.size(); ++t) {
    if (!collapser.face_alive(int32_t(t))) continue;
    const int32_t* c = &triangles[3 * t];
    const double* p[3] = {collapser.position(c[0]), collapser.position(c[1]), collapser.position(c[2])};
    double point[3];
    for (int i = 0; i < 3; ++i) point[i] = (p[0][i] + p[1][i] + p[2][i]) / 3.0;
    double best = distance2(point);
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) point[i] = 0.5 * (p[j][i] + p[(j + 1) % 3][i]);
      best = std::max({best, distance2(point), distance2(p[j])});
    }
    for (int j = 0; j < 3; ++j) back2[c[j]] = std::max(back2[c[j]], best);
  }
  for (int32_t v = 0; v < n; ++v) out.vertex2[v] = std::max(out.vertex2[v], back2[survivor[v]]);
  out.top2 = n > 0 ? *std::max_element(out.vertex2.begin(), out.vertex2.end()) : 0.0;
  return out;
}

}  // namespace topstoc
