// Shortening a simple closed loop on a surface without changing its homotopy class.
//
// The loop is tightened like a rubber band: a window of consecutive loop edges is replaced by
// the shortest path between its two ends inside a topological disk grown around the window.
// Both paths lie in the disk, which is simply connected, so they are homotopic with fixed
// ends and the loop keeps its free homotopy class (hence its homology class: a handle stays a
// handle). The disk grows face by face from the window and only takes a face that meets it
// along one edge with a new vertex, or along two edges (a simplicial collapse in reverse), so
// it stays a disk without any global test. The new path avoids the loop's other vertices, so
// the loop stays simple; a window is replaced only when that makes the loop strictly shorter.
//
// Local moves stall where the loop must move as a whole, like a ring on an hourglass that would
// slide to the waist: every partial move needs two jogs that cost more than it saves. Band moves
// fix that: a disk is grown in a band around the loop until it cannot grow further; the band's
// edges between two disk vertices that are not in the disk ("chords") close cycles, and those in
// the loop's integer homology class cross the band once. The shortest such cycle (a chord plus
// a shortest path in the disk) replaces the loop when shorter: the best loop of the class in
// the band, found with one bounded Dijkstra per chord.
#pragma once

#include <cstdint>
#include <vector>

#include "topology/homology.hpp"
#include "topstoc/core/progress.hpp"
#include "topology/shortest_paths.hpp"
#include "topology/closed_surface.hpp"

namespace topstoc {

struct TightenParams {
  int32_t max_window = 192;    ///< longest window, in edges (shorter loops use half their length)
  int32_t max_region = 40000;  ///< faces in the disk around one window
  int32_t max_rounds = 12;     ///< sweeps over the loop
  int32_t band_rings = 0;      ///< band radius in rings for band moves (0: from the loop's length)
};

class LoopTightener {
 public:
  /// edge_weight: per surface edge (length, or 1 to count edges). Band moves need `homology`
  /// (without it only local moves are made).
  LoopTightener(const ClosedSurface& surface, const std::vector<double>& edge_weight,
                const SurfaceHomology* homology = nullptr);

  /// Returns the tightened loop (never longer; the input when nothing shortens it).
  std::vector<int32_t> tighten(std::vector<int32_t> loop, const TightenParams& params = {}, Progress* progress = nullptr);

 private:
  bool improve_window(std::vector<int32_t>& loop, size_t start, int32_t window, const TightenParams& params);
  bool improve_band(std::vector<int32_t>& loop, int32_t rings, const TightenParams& params);
  void grow_disk(const std::vector<int32_t>& around, int32_t seed_face, int32_t rings, int32_t max_region, bool along);
  uint64_t edge_hash(int32_t e, bool forward) const;

  const ClosedSurface& surface_;
  const std::vector<double>& weight_;
  const SurfaceHomology* homology_;
  std::vector<uint64_t> coefficient_;  // random weights of the homology coordinates (class hashes)
  ShortestPaths paths_;
  uint32_t stamp_ = 0;
  std::vector<uint32_t> vertex_stamp_, face_stamp_, edge_stamp_, ring_stamp_;
  std::vector<int32_t> vertex_faces_, edge_faces_, ring_;  // faces of the disk at each vertex / edge; hop distance
  std::vector<int32_t> source_;   // index of the nearest vertex of `around`
  std::vector<int32_t> on_loop_;  // position on the loop, or -1
  std::vector<int32_t> queue_, disk_vertices_;
  std::vector<uint64_t> hash_;    // class hash of the disk tree path to each vertex
  std::vector<uint32_t> tree_seen_;
  uint32_t tree_stamp_ = 0;
};

/// Tightens every loop in place (tighten with `params`) on the calling thread's team, one
/// LoopTightener per member: a loop's result depends on that loop alone, not on the team size or
/// on which member took it. Only member 0 reports to `progress`; when it cancels, the others stop
/// taking loops.
void tighten_loops(const ClosedSurface& surface, const std::vector<double>& edge_weight, const SurfaceHomology* homology,
                   std::vector<std::vector<int32_t>>& loops, const TightenParams& params, Progress* progress);

}  // namespace topstoc
