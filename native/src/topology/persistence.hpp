// Handle and tunnel cycles by persistent homology (thesis 3.2.4; Dey, Li, Sun 2007).
//
// A filtration adds the surface's simplices first, then the inside's (vertices, edges,
// triangles, tetrahedra). After the surface, 2g edges remain unpaired; an inside triangle that
// pairs one of them kills a surface cycle that bounds inside: a handle cycle. A second
// filtration, the surface then the outside, gives the g tunnel cycles. (One filtration surface
// < inside < outside, as in the thesis, pairs the right generator edges, but its tunnel cycles
// bound chains that may use inside triangles too, so they can carry a handle component: two
// filtrations keep the two subspaces exact.) Each cycle is the reduced column of its killing
// triangle; as everything older than the generator edge is on the surface, so is the cycle.
// Pairing uses PHAT's twist reduction with bit-tree pivot columns (the column type makes a
// 70x difference), restricted to the triangle and tetrahedron columns that decide it.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/core/progress.hpp"
#include "topology/closed_surface.hpp"
#include "topstoc/topology/tetrahedralize.hpp"

namespace topstoc {

struct PersistentCycle {
  bool handle = false;          ///< killed inside (handle) or outside (tunnel)
  int32_t generator_edge = -1;  ///< the unpaired surface edge the killing triangle pairs (surface edge id)
  std::vector<int32_t> edges;   ///< the cycle: surface edge ids, each once (a Z2 cycle, not always simple)
};

/// Pairs the filtrations surface < inside and surface < outside of `tets` (made from `surface`)
/// and returns the 2g cycles, handles first. Throws std::logic_error if the counts are not g and g.
std::vector<PersistentCycle> handle_tunnel_cycles(const ClosedSurface& surface, const TetMesh& tets, Progress* progress = nullptr);

}  // namespace topstoc
