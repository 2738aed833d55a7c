// Filtered vertex placement (docs/design.md §2.9): instead of keeping each sample where it is, move it to
// the point that minimises the summed squared distance to the planes of its cluster's
// triangles (quadric error, Garland & Heckbert 1997, as used for vertex clustering by
// Lindstrom 2000). Small eigenvalues of the quadric are truncated so that flat and cylindrical
// clusters move only along directions the geometry constrains, and no point moves farther than
// the cluster's own radius. Samples on feature curves and corners stay put, so borders, UV seams
// and boundaries keep their exact positions.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/decimate/clustering.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

/// Returns 3 coordinates per sample.
std::vector<double> filtered_positions(const Mesh& mesh, const FeatureLayout& layout,
                                       const std::vector<int32_t>& samples, const Clustering& clustering);

}  // namespace topstoc
