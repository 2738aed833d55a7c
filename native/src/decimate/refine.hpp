// Quadric refinement: a TopStoc result with a few times the wanted vertices, thinned to the
// target by greedy edge collapses ordered by quadric error (Garland & Heckbert 1997).
//
// The stochastic pass does the heavy lifting on the full mesh (fast, topology checked); the
// collapses then pick which of its vertices to drop by how far that takes the surface from the
// *input* (each output vertex carries the summed quadric of the input triangles of its cluster).
// An edge between two free vertices (off every border curve, not locked) collapses to the point
// minimising the summed quadric (Garland & Heckbert's optimal placement; near-singular quadrics
// and optima far from the edge fall back to the best point on the edge). Any other collapse
// moves vertex u onto its neighbour v (a half-edge collapse), so border vertices remain input
// vertices. A collapse is done only if it keeps every guarantee of the decimation: the link
// condition holds (so the surface stays a manifold of the same topology), no triangle around
// either end flips, folds (normal turned by more than ~80 degrees), loses all area or ends
// thinner than shape quality 0.1 (0.05 for one thinner already) and than the thinnest triangle
// around it was, and a vertex on a
// border curve (boundary, UV seam, material border, flagged edge) moves only along its curve,
// onto the next vertex of the same curve or a corner, so borders keep their course and their
// sides and attributes keep carrying over exactly. Corners never move, closed curves keep three
// vertices. User guidance sets per-region quotas (RefineParams); control points are never removed.
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/decimate/collapse_snapshots.hpp"
#include "topstoc/decimate/decimate.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/core/mesh.hpp"

namespace topstoc {

/// The max-aware reruns (and the copies of the collapse state they keep) run on a whole input of
/// at most this many vertices: a UV sphere of 990,002 vertices collapsed whole at 10 % took 35 s
/// and 1.9 GB with them, 20 s and 0.64 GB without.
constexpr int32_t kMaxAwareVertices = 250000;

/// Whether the collapses' start depends on their target: from a partial first pass (not the
/// whole mesh) the planes of feature edges are weighed by the target's output spacing
/// (cluster_quadrics), so a state kept toward one target serves no other.
inline bool start_depends_on_target(const FeatureLayout& layout, bool whole_input) {
  return !whole_input && !layout.feature_edges.empty();
}

struct RefineParams {
  int32_t target_vertices = 0;
  /// > 0: collapse until this many triangles remain instead (the vertex target then only sets
  /// the guidance quotas).
  int32_t target_triangles = 0;
  /// The guidance as density multipliers per internal vertex (guidance_multipliers), or null.
  /// Painted regions keep their share of the budget: the input vertices are binned by their
  /// multiplier m, each bin gets the quota sum over its vertices of min(1, k m) with k solved
  /// so that the quotas sum to the target (the fast mode's expected count with a flat
  /// importance), and collapses stop taking vertices from a bin at its quota. Only when some
  /// bin cannot reach its quota do the others give more. m = 0 (u = -1) has quota 0; control
  /// points (u = 1) are never removed. Removing a vertex also costs m times its quadric error.
  const std::vector<double>* multipliers = nullptr;
  /// Only collapse edges of zero-area triangles (what an input with collinear vertices can
  /// leave after the stochastic pass); every refinement ends with this step too.
  bool zero_area_only = false;
  /// Finally move every free vertex to its quadric's minimum (filtered placement on the final
  /// clusters): what placement="filtered" means for a refined result.
  bool refit = false;
  /// When the first pass kept every vertex (a mesh small enough to collapse whole, or mostly of
  /// slivers) and there are at most 250,000 of them, rerun the last collapses, each vertex's
  /// cost weighed by how far the runs before ended from the input there, and keep the best run
  /// (a smaller max error, for the time of the reruns).
  bool max_aware = false;
  /// With refit and max_aware: results above kFitFaces are fitted too (DecimateParams::large_fit).
  bool large_fit = false;
  /// Every collapse a half-edge collapse (no optimal placement): the output keeps input
  /// positions, as fast mode promises.
  bool keep_positions = false;
  /// Collapse states of earlier max-aware refinements of this mesh and layout, or null: a run
  /// toward a lower vertex target resumes from one (unguided vertex targets only; the same result).
  CollapseSnapshots* snapshots = nullptr;
  /// Stop once the kept state and input surface a later refinement reuses are made
  /// (DecimateParams::warm_up): the result is left unfinished.
  bool warm_up = false;
  CornerAttributes attributes;
};

/// True when some output triangle of `result` has zero area.
bool has_zero_area(const DecimateResult& result);

/// Whether more than a quarter of the mesh's triangles are slivers (shape quality 4 sqrt(3) area
/// / sum of squared edges below 0.1; 1 for an equilateral triangle): a UV sphere of many
/// segments, a CAD tessellation's long strips.
/// Computed once per mesh and kept with the layout (every decimation reads it).
bool sliver_heavy(const Mesh& mesh, const FeatureLayout& layout);

/// Thins `result` (a finished decimation of `mesh`, in the caller's ids) to
/// params.target_vertices output vertices where collapses allow; updates every field of the
/// result (kept, positions, triangles, sources, labels) and its refine_* figures. The sample
/// list is left as it was: replaying it with the same target reproduces the result.
void refine_by_collapses(const Mesh& mesh, const FeatureLayout& layout, const RefineParams& params,
                         DecimateResult& result);

}  // namespace topstoc
