// The wedges of each cluster (Hoppe 1999): the corners of a refinement vertex's input triangles
// grouped by attribute value, so that the two sides of a UV seam or hard edge keep their own
// attribute quadric (vertex_quadrics.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/decimate.hpp"

namespace topstoc {

/// Per corner 3 f + j of the prepared mesh, the wedge of its cluster label[faces[3 f + j]] it
/// belongs to, in [0, max_wedges) (0 where the corner has no cluster). Two corners are one wedge
/// when they are at the same input vertex with equal attribute values, or on the same triangle
/// in the same cluster (a triangle never straddles a seam); wedges past max_wedges share the last.
std::vector<uint8_t> corner_wedges(const Mesh& mesh, const CornerAttributes& attributes,
                                   const std::vector<int32_t>& label, int32_t clusters, int max_wedges);

}  // namespace topstoc
