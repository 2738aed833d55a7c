#include "topstoc/decimate/flood_cache.hpp"

namespace topstoc {

// Updating relabels every vertex (one pass), then refills the clusters of removed samples
// from around them and lets added samples take their share. A fresh flood fills everything.
// Removed samples cost about three times what added ones do (a whole cluster refilled against
// part of one taken over), so a draw updates when added + 3 removed is at most the samples
// drawn (the runs behind the factor: docs/benchmarks.md).
bool FloodCache::worth_updating(const std::vector<int32_t>& drawn) const {
  // Both lists are increasing: a merge, without branches (which side advances is a coin toss
  // for the predictor).
  size_t shared = 0;
  for (size_t i = 0, j = 0; i < samples.size() && j < drawn.size();) {
    const int32_t a = samples[i], b = drawn[j];
    shared += a == b;
    i += a <= b;
    j += b <= a;
  }
  const size_t removed = samples.size() - shared, added = drawn.size() - shared;
  return added + 3 * removed <= drawn.size();
}

void FloodCache::clear() {
  mesh = layout = 0;
  samples = {};
  clustering = {};
  first_check = {};
}

std::unique_ptr<FloodCache> FloodCachePool::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!free_.empty()) {
    auto cache = std::move(free_.back());
    free_.pop_back();
    return cache;
  }
  if (made_ >= capacity_) return nullptr;
  ++made_;
  return std::make_unique<FloodCache>();
}

void FloodCachePool::give_back(std::unique_ptr<FloodCache> cache) {
  if (!cache) return;
  std::lock_guard<std::mutex> lock(mutex_);
  free_.push_back(std::move(cache));
}

void FloodCachePool::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  made_ -= free_.size();
  free_.clear();
}

size_t FloodCachePool::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return made_;
}

}  // namespace topstoc
