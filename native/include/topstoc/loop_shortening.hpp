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
#pragma once

#include <cstdint>
#include <vector>

#include "topstoc/progress.hpp"
#include "topstoc/shortest_paths.hpp"
#include "topstoc/surface.hpp"

namespace topstoc {

struct TightenParams {
  int32_t max_window = 192;    ///< longest window, in edges (shorter loops use half their length)
  int32_t max_region = 40000;  ///< faces in the disk around one window
  int32_t max_rounds = 12;     ///< sweeps over the loop
};

class LoopTightener {
 public:
  /// edge_weight: per surface edge (length, or 1 to count edges).
  LoopTightener(const Surface& surface, const std::vector<double>& edge_weight);

  /// Returns the tightened loop (never longer; the input when nothing shortens it).
  std::vector<int32_t> tighten(std::vector<int32_t> loop, const TightenParams& params = {}, Progress* progress = nullptr);

 private:
  bool improve_window(std::vector<int32_t>& loop, size_t start, int32_t window, const TightenParams& params);
  void grow_disk(const std::vector<int32_t>& window, int32_t rings, int32_t max_region);

  const Surface& surface_;
  const std::vector<double>& weight_;
  ShortestPaths paths_;
  uint32_t stamp_ = 0;
  std::vector<uint32_t> vertex_stamp_, face_stamp_, edge_stamp_, ring_stamp_;
  std::vector<int32_t> vertex_faces_, edge_faces_, ring_;  // faces of the disk at each vertex / edge; hop distance
  std::vector<int32_t> on_loop_;  // position on the loop, or -1
  std::vector<int32_t> queue_;
};

}  // namespace topstoc
