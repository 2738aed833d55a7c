// A Collapser's setup for a test mesh (shared by the collapser tests).
#pragma once

#include <cstdint>

#include "decimate/collapser.hpp"
#include "meshes.hpp"

namespace topstoc_test {

// A torus (no borders, no feature curves), its plane quadrics summed at the corners.
inline topstoc::CollapseSetup torus_setup(const Arrays& mesh) {
  const int32_t n = int32_t(mesh.positions.size() / 3);
  topstoc::CollapseSetup s;
  s.quadrics = topstoc::VertexQuadrics(n, 0);
  for (size_t t = 0; 3 * t < mesh.triangles.size(); ++t) {
    const int32_t* c = &mesh.triangles[3 * t];
    double plane[10], area;
    if (!topstoc::VertexQuadrics::plane(&mesh.positions[3 * size_t(c[0])], &mesh.positions[3 * size_t(c[1])],
                                        &mesh.positions[3 * size_t(c[2])], plane, &area))
      continue;
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 10; ++k) s.quadrics.at(c[j])[k] += plane[k];
  }
  s.positions = mesh.positions;
  s.world = mesh.positions;
  s.weight.assign(n, 1.0);
  s.locked.assign(n, 0);
  s.curve.assign(n, -1);
  s.corner_sector.assign(mesh.triangles.size(), 0);
  s.bin.assign(n, 0);
  s.quota = {0};  // no bin holds vertices back
  return s;
}

}  // namespace topstoc_test
