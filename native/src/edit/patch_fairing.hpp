// Optional finishing of a hole patch (Liepa 2003, "Filling holes in meshes"): refinement adds
// vertices until the patch's edge lengths match the surface around the hole, then fairing moves
// the added vertices to minimise a discrete thin-plate energy (the sum of squared umbrella
// Laplacians over the patch and its boundary), so the patch continues the surrounding surface
// smoothly instead of spanning the hole flat.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "topstoc/edit/polygon_triangulation.hpp"

namespace topstoc {

/// The surface around a patch: for each boundary corner, its neighbours outside the patch
/// (every mesh neighbour but the two next to it along the hole). They stay fixed.
struct PatchRing {
  std::vector<std::vector<std::array<double, 3>>> outer;
};

/// A patch: k boundary corners (fixed; triangle corner ids < k) and added vertices (ids k + j).
struct PatchMesh {
  std::vector<double> boundary;  ///< 3 per boundary corner
  std::vector<double> added;     ///< 3 per added vertex
  std::vector<std::array<int32_t, 3>> triangles;
};

/// Splits triangles at their centroid while they are coarser than the surrounding edge lengths
/// (Liepa's sqrt(2) rule), flipping interior edges towards Delaunay after each round. Never
/// creates an edge between boundary corners that `forbidden` rejects, nor a duplicate edge.
/// Adds at most 50 vertices per boundary corner.
void refine_patch(PatchMesh& patch, const PatchRing& ring, const ForbiddenDiagonal& forbidden);

/// Moves the added vertices to minimise the thin-plate energy (uniform umbrella weights),
/// boundary and ring fixed; conjugate gradients on the normal equations.
void fair_patch(PatchMesh& patch, const PatchRing& ring);

/// Splits every patch triangle of aspect above max_aspect (a sliver: a faired patch of a small
/// hole can be the hole's own triangle) at its centroid, and lifts the new vertex off the
/// sliver's plane to the side fairing bends it, to where its three triangles are within
/// max_aspect, or as near as they get. A patch within max_aspect is left as it is.
void lift_slivers(PatchMesh& patch, const PatchRing& ring, double max_aspect);

}  // namespace topstoc
