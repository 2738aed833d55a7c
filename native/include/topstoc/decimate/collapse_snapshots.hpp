// Collapse states kept between quality decimations of one mesh and feature layout (the live
// preview asks for one ratio after another). A mesh collapsed whole goes the same way toward
// every vertex target until its batches start to depend on the target (they shrink near it):
// a run toward a lower target resumes from the state an earlier run kept there, with the same
// result to the bit. The input's search structure for the distance passes is kept with them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

namespace topstoc {

struct InputSurface;

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
  /// Keeps a state; beyond the capacity the oldest is dropped, except the one for the highest
  /// target (which serves every lower one).
  void keep(std::shared_ptr<const Entry> entry);
  /// The input's search structure for the refinement's distance passes (deviation.hpp), kept
  /// with the states: the one kept under `key` (input_surface_key), else the one `make` makes,
  /// kept instead.
  std::shared_ptr<const InputSurface> input_surface(const std::vector<uint64_t>& key,
                                                    const std::function<std::shared_ptr<const InputSurface>()>& make);
  /// Frees every kept state and the search structure.
  void clear();
  /// States kept.
  size_t size() const;

 private:
  mutable std::mutex mutex_;
  size_t capacity_;
  std::vector<std::shared_ptr<const Entry>> entries_;  // the most recently kept last
  std::vector<uint64_t> surface_key_;
  std::shared_ptr<const InputSurface> surface_;
};

}  // namespace topstoc
