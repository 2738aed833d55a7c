// Emission of the decimated triangles from a clustering, and the check that the clustering
// yields a mesh homeomorphic to the input (closed ball property, Edelsbrunner & Shah 1997).
//
// Work happens on the mesh cut along the feature edges, where each side of a border is a
// surface with boundary of its own. The clustering passes when
//   - every vertex is reached;
//   - every cluster is one closed disk per side it touches: six times its Euler characteristic
//     (sum of per-vertex constants, corrected along cluster borders) equals six times the
//     number of sectors at its sample;
//   - every two clusters meet in one arc per side: the decimated edge between them has exactly
//     the triangles expected (two inside a surface, one per side along a feature curve);
//   - every three clusters meet at most once: no duplicate triangle (a triangle emitted twice
//     with opposite orientations is dropped instead, see partition.cpp);
//   - the triangles around every manifold sample form a single fan;
//   - every closed feature curve is split among at least three clusters;
//   - every component keeps its Euler characteristic (the final safety net).
// Each failure names the clusters to split; the decimation adds samples there and re-floods.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/clustering.hpp"
#include "topstoc/features.hpp"
#include "topstoc/mesh.hpp"

namespace topstoc {

struct PartitionIssues {
  int32_t unreached = 0;   ///< vertices no sample reaches
  int32_t non_disk = 0;    ///< clusters that are not one disk per side
  int32_t bad_edge = 0;    ///< cluster pairs meeting in more or fewer arcs than expected
  int32_t duplicate = 0;   ///< decimated triangles emitted twice
  int32_t bad_link = 0;    ///< samples whose triangles do not form one fan
  int32_t short_loop = 0;  ///< closed feature curves with fewer than three clusters
  int32_t isolated = 0;    ///< required samples (corners, control points) without a triangle
  int32_t sliver = 0;      ///< decimated triangles of (numerically) zero area
  int32_t bad_component = 0;  ///< components whose Euler characteristic changed
  int32_t pillows = 0;     ///< opposite triangle pairs dropped (not an issue: see partition.cpp)
  int32_t absorbed = 0;    ///< samples left without triangles, absorbed by a neighbour (not an issue)
  int32_t topological() const {
    return unreached + non_disk + bad_edge + duplicate + bad_link + short_loop + isolated + bad_component;
  }
};

struct Partition {
  std::vector<int32_t> triangles;    ///< 3 sample ranks per decimated triangle, input orientation
  std::vector<int32_t> source_face;  ///< mesh face each triangle was emitted from
  PartitionIssues issues;
  std::vector<int32_t> split_clusters;  ///< ranks of clusters to split (sorted, unique)
  std::vector<int32_t> new_samples;     ///< vertices to add as samples directly
  std::vector<uint8_t> absorbed;        ///< per rank: 1 if the sample has no triangle (not in the output)
};

/// Emits triangles and checks the partition. `required` marks vertices whose samples must
/// appear in the output (corners, control points); other samples left without a triangle are
/// absorbed by their neighbours. candidate_faces, if given, lists (in increasing order) a
/// superset of the faces whose corners lie in more than one cluster (the fast path);
/// otherwise every face is scanned.
Partition check_partition(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                          const Clustering& clustering, const std::vector<uint8_t>& required, bool check_slivers,
                          const std::vector<int32_t>* candidate_faces = nullptr);

}  // namespace topstoc
