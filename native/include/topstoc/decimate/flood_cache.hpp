// What one decimation leaves for the next on the same mesh and feature layout: the flood of
// its drawn samples (before any repair), which faces that flood emits, and what its first
// check found.
//
// A slider drag asks for nearby targets with the same seed, and their draws share most samples
// (a small step keeps nearly all of them and adds a few percent). A decimation given a
// cache turns the cached flood into its own with flood_update (clustering.hpp), re-tests only
// the faces around the vertices that changed and evaluates only the samples whose triangles
// changed, which gives exactly the clustering, the emitting faces and the issues a fresh flood
// gives: the result is the same mesh, only sooner. Draws that share little (another seed, a far
// lower target) flood afresh and refill the cache.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "topstoc/core/mesh.hpp"
#include "topstoc/decimate/clustering.hpp"
#include "topstoc/decimate/features.hpp"
#include "topstoc/decimate/partition.hpp"

namespace topstoc {

struct FloodCache {
  uint64_t mesh = 0, layout = 0;         ///< serials of what the cache was made on (0: empty)
  std::vector<int32_t> samples;          ///< the drawn samples (increasing vertex ids)
  Clustering clustering;                 ///< flood(samples)
  CheckState first_check;                ///< what the first check of that flood found (its emitting
                                         ///< faces, triangles and per-sample findings, where valid)

  bool holds(const Mesh& m, const FeatureLayout& l) const {
    return mesh == m.serial() && layout == l.serial && clustering.num_vertices() == m.num_vertices();
  }
  /// True when updating this cache to `drawn` is cheaper than a fresh flood.
  bool worth_updating(const std::vector<int32_t>& drawn) const;
  void clear();
};

/// The caches of one mesh and layout, shared by the threads that decimate it: each decimation
/// takes one that no other is using (or a new one, up to `capacity`) and gives it back. The
/// preview's two workers thus each find the flood of the request before their last.
/// Memory: 9 bytes per vertex, 1 per triangle, 17 per emitted triangle and 9 per sample per cache.
class FloodCachePool {
 public:
  explicit FloodCachePool(size_t capacity = 2) : capacity_(capacity) {}
  /// A cache to use alone, or null when all are in use.
  std::unique_ptr<FloodCache> take();
  void give_back(std::unique_ptr<FloodCache> cache);
  /// Frees every cache not in use.
  void clear();
  /// Caches made so far and not freed (in use or not).
  size_t size() const;

 private:
  mutable std::mutex mutex_;
  size_t capacity_;
  size_t made_ = 0;
  std::vector<std::unique_ptr<FloodCache>> free_;  // the most recently given back last
};

}  // namespace topstoc
