// A coarse version of a mesh for the loop computation (thesis 5.2.2): a TopStoc decimation
// that keeps the topology of every component and, for the components that matter, does not
// intersect itself, so that TetGen can tetrahedralize it.
//
// Decimation keeps topology but not embedding: where a shape is thin (turbine blades, the
// two sides of a fin), coarse triangles cut through the opposite side. Every round finds the
// intersecting triangles exactly and splits the clusters of their corners in three by adding,
// in each, the vertex farthest from its sample and the vertex farthest from both; the
// decimation is then redone from the enlarged sample list. Only thin places get finer, so the
// coarse mesh stays small.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "topstoc/decimate/decimate.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/core/progress.hpp"
#include "topology/closed_surface.hpp"

namespace topstoc {

struct CoarseMesh {
  DecimateResult decimation;              ///< labels: cluster of each input vertex; kept: sample of each coarse vertex
  std::unique_ptr<Mesh> mesh;             ///< the decimated mesh, prepared
  std::vector<std::vector<int32_t>> components;  ///< vertices of each component of `mesh`
  std::vector<SurfaceCheck> checks;       ///< per component of `mesh`
  std::vector<int32_t> fine_component;    ///< per component of `mesh`: the input component it stands for
  bool topology_kept = false;             ///< the decimation reported no remaining topological issue
  int32_t intersecting = 0;               ///< triangle pairs still intersecting in the wanted components
  int32_t rounds = 0;                     ///< refinement rounds
  int32_t samples_added = 0;              ///< samples added against self-intersections
};

/// Decimates `mesh` to about `target` vertices, then refines until the components standing for
/// input components with wanted[c] != 0 are free of self-intersections (or max_rounds is hit).
std::unique_ptr<CoarseMesh> make_coarse_mesh(const Mesh& mesh, int32_t target, uint64_t seed,
                                             const std::vector<uint8_t>& wanted, int32_t max_rounds = 10,
                                             Progress* progress = nullptr);

}  // namespace topstoc
