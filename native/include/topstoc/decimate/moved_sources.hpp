// Where the attributes of output vertices that moved (quality mode's placement) come from: the
// closest input triangle touching the vertex's cluster and barycentric weights in it
// (addon/core/carry/attributes.py's moved_vertices, docs/design.md §1.3).
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"

namespace topstoc {

struct MovedSources {
  std::vector<int64_t> face;    ///< per output vertex: input triangle, -1 for vertices not moved
  std::vector<double> weights;  ///< 3 per output vertex, in [0, 1], summing to 1 ((1, 0, 0) if not moved)
};

/// input: 3n positions; triangles: 3m caller vertex ids; labels: the output vertex of each input
/// vertex's cluster (-1: none); output: 3k positions; moved: k flags. For each moved output
/// vertex, among the input triangles with a corner in its cluster, the one whose clamped
/// projection is closest (the lowest triangle on ties), with the clamped barycentric weights.
MovedSources moved_sources(const double* input, const int32_t* triangles, int64_t num_triangles,
                           const int32_t* labels, const double* output, const uint8_t* moved, int64_t num_output);

/// The same, read from the prepared mesh of the input instead of the caller's arrays (a big
/// decimation need not take them back), for a mesh that dropped no triangle; labels are the
/// caller's. Moved: the output vertices not at the position of their kept input vertex.
MovedSources moved_sources(const Mesh& mesh, const int32_t* labels, const int32_t* kept, const double* output,
                           int64_t num_output);

}  // namespace topstoc
