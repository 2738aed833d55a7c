// Emission of the decimated triangles from a clustering, and the checks that the result is
// homeomorphic to the input.
//
// Each input face whose corners lie in three clusters emits the triangle of those clusters'
// samples. The result is accepted when, per component of the input,
//   - every vertex is reached by some sample;
//   - the triangles around every manifold sample form one consistently oriented fan;
//   - every decimated edge has the triangles expected: two inside a surface, one per side
//     along a feature curve (boundary: one, border between two regions: two, ...);
//   - no triangle appears twice (a triangle emitted twice with opposite orientations, around a
//     cluster that has no other triangle, is dropped instead: see partition.cpp);
//   - every closed feature curve is split among at least three clusters;
//   - the Euler characteristic is unchanged.
// A manifold, consistently oriented result with the same Euler characteristic and the same
// boundary loops as the input component is homeomorphic to it (classification of surfaces),
// so these output checks are the guarantee. When only the Euler characteristic fails, the
// clusters that are not disks (closed ball property, Edelsbrunner & Shah 1997) are located on
// the mesh cut along the features and split. Each failure names the clusters to split; the
// decimation adds samples there and re-floods.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "topstoc/decimate/clustering.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

struct PartitionIssues {
  int32_t unreached = 0;      ///< vertices no sample reaches
  int32_t non_disk = 0;       ///< clusters that are not one disk per side (diagnosis only)
  int32_t bad_edge = 0;       ///< cluster pairs with more or fewer triangles than expected
  int32_t duplicate = 0;      ///< decimated triangles emitted twice
  int32_t bad_link = 0;       ///< samples whose triangles do not form one oriented fan
  int32_t short_loop = 0;     ///< closed feature curves with fewer than three clusters
  int32_t isolated = 0;       ///< required samples (corners, control points) without a triangle
  int32_t bad_component = 0;  ///< components whose Euler characteristic changed
  int32_t sliver = 0;         ///< decimated triangles of (numerically) zero area
  int32_t pillows = 0;        ///< opposite triangle pairs dropped (not an issue)
  int32_t absorbed = 0;       ///< samples left without triangles, absorbed by a neighbour (not an issue)
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

/// The triangles a check emitted, in face order: a later check over nearly the same clustering
/// (a repair round, or a slider frame from a kept flood) takes them over (FloodCache keeps one).
struct EmittedTriangles {
  std::vector<int32_t> faces;      ///< every triangle emitted (pillows included): source face
  std::vector<int32_t> triangles;  ///< ... and its 3 sample ranks
  std::vector<uint8_t> sliver;     ///< ... and whether it has zero area (if slivers_checked)
  bool slivers_checked = false;
  /// Puts the triangles in the ranks of another sample list (flood_update's new_rank; a
  /// removed sample's triangles are all re-tested, so its -1 is never read).
  void renumber(const std::vector<int32_t>& new_rank) {
    for (int32_t& rank : triangles) rank = new_rank[rank];
  }
};

/// What a check found from each sample's link (the triangles around it). A later check over
/// nearly the same triangles evaluates only the samples whose link changed and takes the
/// others' over (FloodCache keeps one).
struct SampleLinks {
  int32_t samples = 0;                                      ///< how many samples (those appended later are new)
  std::vector<int64_t> chi6;                                ///< per sample: its Euler contribution, times 6
  std::vector<uint8_t> absorbed;                            ///< per sample: no triangle, absorbed
  std::vector<int32_t> revisit;                             ///< samples to evaluate again whatever changes
  std::vector<uint64_t> seen_pairs;                         ///< feature pairs found in a link, sorted
  std::vector<std::pair<uint64_t, int32_t>> feature_pairs;  ///< feature pairs and their copies, sorted
  /// Puts everything in the ranks of another sample list of `count` samples (flood_update's
  /// new_rank, -1 for a removed sample). Samples that are new or absorbed (whether a sample
  /// may be absorbed depends on the decimation's control points) join the revisit list; pairs
  /// with a removed sample are dropped.
  void renumber(const std::vector<int32_t>& new_rank, int32_t count);
};

/// What the last check of one decimation found, kept for the next round's check. After
/// flood_add only the faces around the vertices that changed are tested again, and only the
/// samples whose link (the triangles around them) may differ are evaluated again: a repair
/// round relabels a few hundred vertices of a mesh of a million.
struct CheckState {
  // Which faces emit a triangle.
  std::vector<uint8_t> emits;    ///< per face: corners in three clusters
  std::vector<int32_t> changed;  ///< vertices relabelled since the last check (flood_add fills it)
  bool valid = false;            ///< emits matches the clustering as of the last check

  // The triangles the last check emitted: a check that re-tests the faces around a few changed
  // vertices takes the others over from here instead of reading every emitting face's labels.
  bool emitted_valid = false;  ///< `emitted` holds the last check's
  EmittedTriangles emitted;

  // The samples' links as the last check evaluated them (needs `emitted` valid too).
  bool links_valid = false;
  SampleLinks links;

  /// Puts the triangles and the per-sample findings in the ranks of flood_update's new sample
  /// list of `count` samples (new_rank: each old sample's new rank, -1 if removed).
  void renumber(const std::vector<int32_t>& new_rank, int32_t count) {
    if (emitted_valid) emitted.renumber(new_rank);
    if (links_valid) links.renumber(new_rank, count);
  }
  /// Keeps only what a later check may take over: a check that stopped at unreached vertices
  /// after re-testing around changed ones leaves `changed` set, and each part needs the one
  /// before it (the links the triangles, the triangles the emits).
  void keep_complete() {
    valid = valid && changed.empty();
    emitted_valid = emitted_valid && valid;
    links_valid = links_valid && emitted_valid;
  }
};

/// Emits triangles and checks them. `required` marks vertices whose samples must appear in the
/// output (control points; empty: none); corners are always required. Other samples left without a
/// triangle are absorbed by their neighbours. candidate_faces, if given, lists (in increasing
/// order) a superset of the faces whose corners lie in three clusters (the fast path, thesis
/// 4.1.1); otherwise every face is scanned.
/// With a CheckState whose emits are valid, only the faces around state->changed are tested;
/// with its links valid too, only the samples whose links may have changed are evaluated (the
/// others keep what the last check found, which is what evaluating them again gives).
Partition check_partition(const Mesh& mesh, const FeatureLayout& layout, const std::vector<int32_t>& samples,
                          const Clustering& clustering, const std::vector<uint8_t>& required, bool check_slivers,
                          const std::vector<int32_t>* candidate_faces = nullptr, CheckState* state = nullptr);

/// Six times the Euler characteristic of every cluster on the mesh cut along the feature
/// edges (one pass over all faces). A cluster is one disk per side exactly when the value is
/// six times the number of sectors at its sample.
std::vector<int64_t> cluster_euler6(const Mesh& mesh, const FeatureLayout& layout, int32_t num_samples,
                                    const Clustering& clustering);

}  // namespace topstoc
