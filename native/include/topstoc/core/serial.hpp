// Serial numbers that tell objects apart for the whole process: a cache keyed by an object's
// address could mistake a new object for a freed one that lived there.
#pragma once

#include <atomic>
#include <cstdint>

namespace topstoc {

/// A number never returned before in this process (from 1).
inline uint64_t new_serial() {
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace topstoc
