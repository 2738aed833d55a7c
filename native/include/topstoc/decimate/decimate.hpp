// TopStoc decimation (thesis 4.1; docs/design.md §2): sample, flood, check, repair, emit.
//
// The output's vertices are input vertices (or, in filtered mode, points near them); every
// output triangle comes from one input triangle whose corners lie in three different clusters,
// and keeps its orientation. When the clustering would break the topology the decimation adds
// samples to the offending clusters and re-floods incrementally until every check passes;
// the result reports how many samples that took. The final sample list, fed back through
// decimate_with_samples, reproduces the identical output.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/decimate/features.hpp"
#include "topstoc/decimate/collapse_snapshots.hpp"
#include "topstoc/decimate/flood_cache.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/partition.hpp"
#include "topstoc/decimate/verify.hpp"
#include "topstoc/decimate/sampling.hpp"

namespace topstoc {

enum class Placement { Subsample, Filtered };

/// Attributes that enter the collapse cost (vertex_quadrics.hpp): per caller corner (3 per
/// caller triangle) `channels` values, each channel's multiplied by its weight before use. An
/// attribute difference d in a channel of weight w costs as much as moving the surface by w d
/// bounding-box diagonals. values null: none.
struct CornerAttributes {
  const double* values = nullptr;
  int channels = 0;
  const double* weights = nullptr;
  /// Up to this many attribute quadrics per vertex (at most 8), one per wedge (the corners that
  /// share values: a seam's two sides), so a seam's jump costs nothing (vertex_quadrics.hpp);
  /// 0 or 1: one per vertex. Meshes whose clusters have one wedge each store one either way.
  int wedges = 4;
};


struct DecimateParams {
  int32_t target_vertices = 0;  ///< wanted output vertices (exact without guidance, before repairs)
  SamplingParams sampling;
  Placement placement = Placement::Subsample;
  int32_t max_repair_rounds = 200;
  /// Collect candidate faces during the flood (thesis 4.1.1) instead of scanning all faces:
  /// -1 below 5 % of the vertices, 0 never (default), 1 always. The scan of all faces' labels
  /// (parallel, streaming) measured faster: the border edges recorded during the flood and the
  /// scattered face marks cost more than the labels they save reading.
  int fast_path = 0;
  int budget_passes = 2;        ///< extra draws when repairs overshoot the target (unguided only)
  /// Quadric refinement (refine.hpp): 0 = off; f > 1 keeps f times the target with TopStoc,
  /// then quadric-ordered collapses thin the result to the target (better error, slower).
  double refine = 0.0;
  /// With refine, C > 0: the first pass keeps at least target + max(C, target / 4) vertices,
  /// and all of them when the mesh has at most 8 C. Small meshes then skip the stochastic
  /// pass, whose choices cost quality; on big ones the collapses' time grows with the target,
  /// not with the mesh, while the stochastic pass does the bulk.
  int32_t refine_collapses = 0;
  /// > 0: the caller's triangle target (decimate_to_triangles). A plain TopStoc pass whose
  /// repairs stalled above the target is collapsed to this many triangles.
  int32_t target_triangles = 0;
  CornerAttributes attributes;  ///< attribute-aware cost of the refinement
  /// Floods of earlier decimations of this mesh and layout (flood_cache.hpp), or null: the
  /// result is the same either way, nearby targets of one seed come sooner (not with the fast
  /// path, whose results can differ from a full scan's). Null also keeps none of the draw's
  /// per-vertex tables on the layout (a caller without floods decimates once; a later draw
  /// rebuilds them, the same bits).
  FloodCachePool* flood_caches = nullptr;
  /// Collapse states of earlier quality decimations of this mesh and layout
  /// (collapse_snapshots.hpp), or null: the same result either way, lower targets sooner.
  CollapseSnapshots* collapse_snapshots = nullptr;
  /// A live-preview frame (plain TopStoc only, refine 0): the output's geometry (samples, kept,
  /// vertices, triangles) without face_source, corner_source and labels, and without the final
  /// output check (verify.hpp) unless the fast path needs it. The partition checks and repairs
  /// run as always, so the mesh is the one a full decimation gives, or its plain pass where
  /// the full decimation collapses that pass further (collapses_skipped); output_checked tells
  /// that it was not re-checked. A frame takes about three quarters of a full decimation's time.
  bool draft = false;
  /// A warm-up (quality decimations with collapse_snapshots only): builds what a later
  /// decimation toward this target or a lower one resumes from, the first collapse run's kept
  /// state (and, for a mesh collapsed whole, the input's search structure), and stops there;
  /// its result is empty. Does nothing where a decimation would keep no state (no snapshots,
  /// guidance, a triangle target, a first pass that depends on the target); refine_vertices > 0
  /// tells it did.
  bool warm_up = false;
  /// A refined result above kFitFaces triangles whose max error the refinement measured (a mesh
  /// collapsed whole) is fitted to the input too, as smaller ones always are (tiny_fit.hpp):
  /// a lower mean error for more time (docs/bench_notes/large-fit.md). The API's mode "best".
  bool large_fit = false;
  /// Internal (a refined decimation's first pass): labels in the mesh's vertex order.
  bool labels_in_mesh_order = false;
};

struct DecimateResult {
  // All vertex ids below are the caller's (see Mesh::vertex_source).
  std::vector<int32_t> samples;        ///< the full sample list: feed it back to reproduce this result
  std::vector<int32_t> kept;           ///< input vertex of each output vertex (samples with triangles)
  std::vector<double> vertices;        ///< positions, 3 per output vertex
  std::vector<int32_t> triangles;      ///< 3 per output triangle, indices into kept
  std::vector<int32_t> face_source;    ///< caller's triangle each output triangle comes from
  std::vector<int32_t> corner_source;  ///< 3 per output triangle: caller's corner 3 * triangle + slot
  std::vector<int32_t> labels;         ///< per input vertex: output vertex of its cluster, -1 if none
  /// Internal: labels are in the mesh's vertex order, not the caller's (a refined decimation's
  /// first pass, whose labels the refinement reads in that order and publishes in the caller's).
  bool labels_in_mesh_order = false;
  int32_t target_vertices = 0;
  int32_t selected = 0;                ///< samples drawn before repairs
  int32_t forced = 0;                  ///< corners and control points among them
  int32_t loop_forced = 0;             ///< of those, three vertices of each short boundary loop (the holes') and the winding seams' (no border's corners)
  int32_t density_rejected = 0;
  bool guided = false;
  double expected_vertices = 0.0;      ///< sum of the sampling probabilities
  double rate = 0.0;                   ///< base rate k used for the probabilities
  bool fast_path = false;
  bool flood_updated = false;          ///< the draw for the target updated a kept flood (flood_cache.hpp)
  // The field names are the Python result's (DecimateStats): the bindings copy, never rename.
  int32_t repair_rounds = 0;           ///< re-flood rounds after the first check
  int32_t repairs = 0;                 ///< samples added to restore topology or shape
  PartitionIssues issues_found;        ///< issues found over all rounds
  PartitionIssues issues_remaining;    ///< issues left when the round limit was hit (normally none)
  int32_t top_up = 0;                  ///< samples added to make up for absorbed clusters
  int32_t top_up_rounds = 0;
  int32_t refine_vertices = 0;         ///< target of the quadric refinement (0: none)
  int32_t refine_triangles = 0;        ///< its triangle target, when it had one (0: none)
  int32_t refine_collapses = 0;        ///< collapses it made
  bool refine_keeps_positions = false; ///< its collapses were half-edge only (fast mode's)
  /// It stopped above its target where only triangles thinner than the input's own needles
  /// would have gone on: a sliver-heavy input, whose collapses without the shape rule would have
  /// gone at least halfway from there to the target (refine.cpp's held_by_shape).
  bool shape_floor = false;
  /// It stopped at twice its target or more where only collapses that flip, fold or thin
  /// triangles would have gone on: without those checks its collapses would have gone at least
  /// halfway from there to the target (refine.cpp's held_by_folds; a thin, curved part).
  bool fold_floor = false;
  /// It stopped above its target where only collapses that lay triangles far from the input
  /// (over an opening) would have gone on: without refine.cpp's far guard, its collapses would
  /// have gone at least halfway from there to the target.
  bool far_guard = false;
  /// A draft above its target, or with zero-area triangles: the collapses that take the full
  /// decimation the rest of the way, or clean those up, were left out (they need the labels a
  /// draft leaves out), so the frame is the plain pass.
  bool collapses_skipped = false;
  double seconds_sampling = 0, seconds_clustering = 0, seconds_checking = 0, seconds_output = 0;
  double seconds_verify = 0;  ///< the final output check (verify.hpp)
  double seconds_refine = 0;
  OutputCheck output_check;            ///< the final check of the output (verify.hpp)
  bool output_checked = false;         ///< the final check ran (always, except for drafts)
};

/// Decimates to params.target_vertices (1 <= target). Throws std::invalid_argument on bad params.
DecimateResult decimate(const Mesh& mesh, const FeatureLayout& layout, const DecimateParams& params);

/// The engine emits and collapses each component in one winding (Mesh::winding_flips): each
/// output triangle whose source face runs against it takes that face's winding back (its second
/// and third corners, and their corner sources, trade places), so the output keeps the input's
/// flipped patches where they were; a component whose output triangles all came from one side
/// of its seams has its first triangle turned (it stays inconsistently oriented, as its input).
/// Nothing to do for a draft (no face sources: its triangles
/// are turned back as they are made) or a consistently oriented input. Whoever hands a result
/// out calls it once (the Python bindings, the command-line driver).
void restore_winding(const Mesh& mesh, DecimateResult& result);

/// Re-creates a decimation from a saved sample list (thesis 4.1.3). A refined result also
/// needs its refine_vertices and the guidance it was made with. Corners the list lacks (feature
/// corners, pinched vertices: always kept) are appended to it.
DecimateResult decimate_with_samples(const Mesh& mesh, const FeatureLayout& layout, std::vector<int32_t> samples,
                                     Placement placement, int32_t max_repair_rounds = 200,
                                     int32_t refine_vertices = 0, const double* guidance = nullptr,
                                     const CornerAttributes& attributes = {}, int32_t refine_triangles = 0,
                                     bool refine_keeps_positions = false, bool large_fit = false);

/// Decimates to about `target_triangles` output triangles (within 1 % where the mesh allows),
/// re-decimating with a corrected vertex target up to `max_iterations` times.
DecimateResult decimate_to_triangles(const Mesh& mesh, const FeatureLayout& layout, DecimateParams params,
                                     int32_t target_triangles, int max_iterations = 6);

}  // namespace topstoc
