// The final check of a decimation's output against its input, run before a result is returned.
//
// The partition checks (partition.hpp) decide where to add samples; this check is independent of
// them and reads only the output arrays, so a blind spot there cannot turn into a silent lie.
// Per input component whose surface is manifold and consistently oriented (or would be, but for
// pinched vertices), the output piece
// must be one connected, manifold (edges and vertices), consistently oriented surface with the
// input's Euler characteristic and number of boundary loops: by the classification of surfaces
// that makes it homeomorphic to the input. At each pinched input vertex every fan must still be
// a fan of its output vertex (same count, open or closed, same sheet: pinched_fans.hpp), since
// no count above sees a bowtie's wing lost or merged there. For every component: no triangle with a repeated
// corner, none twice, no coordinate that is not finite. Zero-area triangles are counted (the
// decimation reports them; an input of collinear vertices may not allow removing them all).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/features.hpp"

namespace topstoc {

struct OutputCheck {
  int32_t nonfinite = 0;              ///< output vertices with a coordinate that is NaN or infinite
  int32_t repeated_corner = 0;        ///< triangles using one vertex twice
  int32_t duplicate = 0;              ///< triangles over the same three vertices as another
  int32_t zero_area = 0;              ///< triangles of (numerically) zero area (reported, not an error)
  int32_t nonmanifold_edges = 0;      ///< output edges with three or more triangles (manifold inputs)
  int32_t nonmanifold_vertices = 0;   ///< output vertices whose triangles are not one fan (manifold inputs)
  int32_t inconsistent_edges = 0;     ///< edges traversed twice in one direction (manifold inputs)
  int32_t mixed_triangles = 0;        ///< triangles joining vertices of different input components
  int32_t lost_components = 0;        ///< input components without an output triangle
  int32_t split_components = 0;       ///< input components whose output falls apart
  int32_t euler_changed = 0;          ///< manifold input components whose Euler characteristic changed
  int32_t boundary_loops_changed = 0; ///< manifold input components whose number of boundary loops changed
  int32_t pinched_fans_changed = 0;   ///< pinched input vertices whose fans are not those of their output vertex

  /// Everything but zero_area: a violation of a promised guarantee.
  int32_t violations() const {
    return nonfinite + repeated_corner + duplicate + nonmanifold_edges + nonmanifold_vertices +
           inconsistent_edges + mixed_triangles + lost_components + split_components + euler_changed +
           boundary_loops_changed + pinched_fans_changed;
  }
  /// "3 non-manifold edges, 1 component whose Euler characteristic changed", or "" when clean.
  std::string describe() const;
};

/// Boundary loops (cycles of edges with one triangle) per component of the mesh, from the
/// layout's list of them (built once per layout, so a re-decimation does not scan the edges).
std::vector<int32_t> component_boundary_loops(const Mesh& mesh, const FeatureLayout& layout);

/// Checks a decimated surface. kept: the input vertex (internal id) of each output vertex;
/// positions: 3 per output vertex; triangles: 3 indices into kept per output triangle.
OutputCheck check_output(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& kept,
                         const std::vector<double>& positions, const std::vector<int32_t>& triangles);

}  // namespace topstoc
