// Generator edges of H1 (thesis 3.2.3, 3.2.4.1 and 4.2.1): for each closed orientable manifold
// component of genus g, the 2g edges that stay unpaired when the component's simplices are
// paired in a filtration (vertices, then edges, then triangles), each with a closed loop
// through it. Together the loops form a basis of the component's first homology over Z2.
//
// The pairing is computed as a tree-cotree decomposition in linear time:
//  - edges are ordered by a breadth-first search from the component's smallest vertex id: first
//    the edges of the search tree T, then the others by the length of the loop they close
//    through T;
//  - vertex-edge pairs: union-find on vertices in that order keeps exactly T (the negative edges);
//  - edge-triangle pairs: union-find on triangles across the remaining edges in reverse order;
//    an edge that joins two groups of triangles belongs to the cotree C (it is paired with a
//    triangle);
//  - the 2g edges in neither T nor C are the unpaired (essential) edges. Processing the cotree
//    in reverse order makes it a maximum spanning tree of the dual graph for the loop lengths,
//    so the basis is the greedy (shortest) system of loops through the root
//    (Erickson and Whittlesey 2005), measured in edges.
// The loop of generator edge (u, v) is that edge plus the tree paths from u and v to their
// lowest common ancestor: a simple closed cycle (the loop through the root minus the shared
// stem). The tree paths joining all loops to each other plus the generator edges form a cut
// graph: cutting the surface along it leaves one disk. All ids are the caller's.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/topology/complex.hpp"
#include "topstoc/topology/topology.hpp"

namespace topstoc {

struct ComponentGenerators {
  int32_t component = 0;  ///< index in TopologyReport::components
  int32_t genus = 0;
  int32_t root = 0;       ///< search-tree root (where the cut graph's trees meet)
  /// 2g generator edges (vertex pairs, lower id first), ordered by the length of their loop,
  /// shortest first.
  std::vector<int32_t> edges;
  /// Loop i (CSR) visits loop_vertices[loop_offsets[i] .. loop_offsets[i+1]): it starts with
  /// generator edge i (its first two vertices) and closes back to its first vertex.
  std::vector<int32_t> loop_offsets = {0};
  std::vector<int32_t> loop_vertices;
  /// Cut graph edges (vertex pairs, lower first, sorted): the generator edges and the tree
  /// edges that join the loops. Empty for genus 0.
  std::vector<int32_t> cut_edges;
};

/// Generators for every closed orientable manifold component of `report` (genus 0 included,
/// with no edges). `report` must come from analyze_topology(complex).
std::vector<ComponentGenerators> compute_generators(const SimplicialComplex& complex, const TopologyReport& report);

}  // namespace topstoc
