// Killing a handle or tunnel (thesis 4.2.2, docs/design.md §4.5): cut the surface along a loop that
// goes around it, then fill the two holes the cut opened. On a closed orientable component of
// genus g this leaves genus g - 1 and changes nothing else: the same number of components and
// boundary loops, every vertex off the loop where it was. The two copies of the loop are first
// pulled a little apart, each into its own side, so that the two patches do not lie on top of
// each other (a cut alone leaves them in the same place).
#pragma once

#include <cstdint>

#include "topstoc/edit/edit.hpp"
#include "topstoc/edit/fill_holes.hpp"

namespace topstoc {

struct RemoveHandleOptions {
  FillOptions fill;
  /// A loop that bounds a disk or splits its component (it goes around no handle) would split
  /// the component in two; that is refused unless allowed here.
  bool allow_separating = false;
  /// Each copy of a loop vertex moves this fraction of the way towards the mean of its
  /// neighbours off the cut (less where a triangle would turn over); 0 keeps the copies in place.
  double separation = 0.25;
  /// By default a result in which a patch or a moved triangle intersects the surface is never
  /// returned: other patches are tried, then std::invalid_argument. True returns the first
  /// candidate whatever it intersects (for callers that only need the topology).
  bool allow_self_intersections = false;
  /// When every patch tried crosses the surface, step down to coarser fills: a refined flat one,
  /// then a flat one (the attempts separate calls with those fills would make, each once).
  bool step_down = false;
};

/// Cuts along the closed edge loop (see cut_along_loop) and fills every side of the cut (see
/// fill_loops). Throws std::invalid_argument for what those reject, for a loop touching the mesh
/// boundary (the cut would merge with that boundary, so boundary loops would change) and for a
/// separating loop unless allowed. The result's cut_sides and patches describe both steps.
EditResult remove_handle(const double* positions, int32_t num_vertices, const int32_t* triangles,
                         int64_t num_triangles, const int32_t* loop, int32_t loop_size,
                         const RemoveHandleOptions& options);

}  // namespace topstoc
