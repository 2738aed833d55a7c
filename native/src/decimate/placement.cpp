#include "decimate/placement.hpp"
#include "topstoc/core/parallel.hpp"
#include "decimate/quadric.hpp"

#include <algorithm>
#include <cmath>

namespace topstoc {

std::vector<double> filtered_positions(const Mesh& mesh, const FeatureLayout& layout,
                                       const std::vector<int32_t>& samples, const Clustering& clustering) {
  const int32_t k = static_cast<int32_t>(samples.size());
  const int32_t n = mesh.num_vertices();
  auto label = [&clustering](int32_t v) { return clustering.label(v); };
  const auto& faces = mesh.faces();
  // Quadrics hold squared areas: with coordinates of 1e80 they overflow (all-NaN output), with
  // 1e-80 they underflow. Work in coordinates centred on the bounding box and scaled by its
  // half extent (halves taken first so that neither the centre nor the extent overflows).
  double low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) low[i] = std::min(low[i], mesh.position(v)[i]), high[i] = std::max(high[i], mesh.position(v)[i]);
  double center[3], extent = 0;
  for (int i = 0; i < 3; ++i) {
    center[i] = n > 0 ? 0.5 * low[i] + 0.5 * high[i] : 0.0;
    extent = std::max(extent, n > 0 ? 0.5 * high[i] - 0.5 * low[i] : 0.0);
  }
  std::vector<double> out(3 * size_t(k));
  for (int32_t s = 0; s < k; ++s)
    for (int i = 0; i < 3; ++i) out[3 * size_t(s) + i] = mesh.position(samples[s])[i];
  if (!(extent > 0) || !std::isfinite(extent)) return out;
  std::vector<double> unit(3 * size_t(n));
  for (int32_t v = 0; v < n; ++v)
    for (int i = 0; i < 3; ++i) unit[3 * size_t(v) + i] = (mesh.position(v)[i] - center[i]) / extent;
  auto at = [&](int32_t v) { return &unit[3 * size_t(v)]; };
  std::vector<Quadric> quadrics(k);
  for (int32_t f = 0; f < mesh.num_faces(); ++f) {
    const int32_t* t = &faces[3 * size_t(f)];
    Quadric plane;
    plane.add_triangle(at(t[0]), at(t[1]), at(t[2]));
    const int32_t l[3] = {label(t[0]), label(t[1]), label(t[2])};
    for (int j = 0; j < 3; ++j)
      if (!((j > 0 && l[j] == l[0]) || (j > 1 && l[j] == l[1]))) quadrics[l[j]].add(plane);  // each cluster once
  }
  // Radius of each cluster around its sample: the bound on how far the sample may move.
  std::vector<double> radius2(k, 0.0);
  for (int32_t v = 0; v < n; ++v) {
    if (label(v) < 0) continue;
    const double* p = at(v);
    const double* s = at(samples[label(v)]);
    const double d2 = (p[0] - s[0]) * (p[0] - s[0]) + (p[1] - s[1]) * (p[1] - s[1]) + (p[2] - s[2]) * (p[2] - s[2]);
    radius2[label(v)] = std::max(radius2[label(v)], d2);
  }
  parallel_for(0, k, kParallelMin, [&](int32_t s) {
    const double* p = at(samples[s]);
    double* x = &out[3 * size_t(s)];
    if (layout.is_feature_vertex(samples[s])) return;
    double move[3];
    if (!quadrics[s].truncated_step(p, move)) return;
    const double len2 = move[0] * move[0] + move[1] * move[1] + move[2] * move[2];
    const double scale = len2 > radius2[s] && len2 > 0 ? std::sqrt(radius2[s] / len2) : 1.0;
    double moved[3];
    for (int i = 0; i < 3; ++i) moved[i] = (p[i] + scale * move[i]) * extent + center[i];
    if (std::isfinite(moved[0]) && std::isfinite(moved[1]) && std::isfinite(moved[2]))
      for (int i = 0; i < 3; ++i) x[i] = moved[i];
  });
  return out;
}

}  // namespace topstoc
