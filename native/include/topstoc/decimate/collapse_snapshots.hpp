// Collapse states kept between quality decimations of one mesh and feature layout (the live
// preview asks for one ratio after another). A mesh collapsed whole goes the same way toward
// every vertex target until its batches start to depend on the target (they shrink near it):
// a run toward a lower target resumes from the state an earlier run kept there, with the same
// result to the bit. The input's search structures for the distance passes and the fit of small
// results are kept with them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace topstoc {

class Surface;

class CollapseSnapshots {
 public:
  /// One kept state (collapse_snapshots.cpp).
  struct Entry;

  explicit CollapseSnapshots(size_t capacity = 2);
  ~CollapseSnapshots();
  CollapseSnapshots(const CollapseSnapshots&) = delete;
  CollapseSnapshots& operator=(const CollapseSnapshots&) = delete;

  /// The kept state a run from `start` (collapse_snapshots.cpp's start_key) toward `vertices`
  /// may resume from: of a run with the same start toward as many vertices or more, the one
  /// with the fewest vertices left; null when there is none.
  std::shared_ptr<const Entry> find(const std::vector<uint64_t>& start, int32_t vertices) const;
  /// Whether a plain run (no max-aware reruns: a mesh too large to collapse whole) keeps its
  /// state: a warm-up's does, and any other from the second such run on. A one-off
  /// decimation's copy (about 450 bytes a first-pass vertex) would sit beside its peak for
  /// nothing.
  bool keeps_plain_run(bool warm_up);
  /// Keeps a state; beyond the capacity the oldest is dropped, except the one for the highest
  /// target (which serves every lower one).
  void keep(std::shared_ptr<const Entry> entry);
  /// The input's triangles with their search structure, for the refinement's distance passes
  /// and the fit (deviation.hpp's normalised_input), kept with the states: the one kept under
  /// `key` (input_surface_key), else the one `make` makes, kept too. At most kSurfaces are kept
  /// (the whole input, and the fit's share of a large one), the least recently used dropped.
  std::shared_ptr<const Surface> input_surface(const std::vector<uint64_t>& key,
                                               const std::function<std::shared_ptr<const Surface>()>& make);
  static constexpr size_t kSurfaces = 2;
  /// Frees every kept state and search structure.
  void clear();
  /// States kept.
  size_t size() const;
  /// Input surfaces kept.
  size_t surfaces() const;
  /// Runs that resumed from a kept state (find found one), and input surfaces made, since made.
  size_t resumed() const;
  size_t surfaces_made() const;

 private:
  mutable std::mutex mutex_;
  size_t capacity_;
  mutable size_t resumed_ = 0;
  size_t plain_runs_ = 0;  // plain runs that asked keeps_plain_run
  size_t surfaces_made_ = 0;
  std::vector<std::shared_ptr<const Entry>> entries_;  // the most recently kept last
  std::vector<std::pair<std::vector<uint64_t>, std::shared_ptr<const Surface>>> surfaces_;  // most recent last
};

}  // namespace topstoc
