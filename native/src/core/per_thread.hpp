// One value per thread (a list a thread appends to, its scratch space), each on cache lines of
// its own.
//
// Kept in a plain std::vector, neighbouring threads' values share a cache line (two vector
// headers fit in one): every push_back writes the list's end pointer, so the line moves
// between the cores on every append (the flood's per-level lists lost a sixth of its time).
#pragma once

#include <vector>

#include "topstoc/core/parallel.hpp"

namespace topstoc {

template <class T>
class PerThread {
 public:
  explicit PerThread(int threads) : slots_(size_t(threads)) {}
  int size() const { return int(slots_.size()); }
  T& operator[](int thread) { return slots_[size_t(thread)].value; }
  const T& operator[](int thread) const { return slots_[size_t(thread)].value; }
  /// The calling thread's value (inside a parallel region; thread 0's outside one).
  T& mine() { return (*this)[thread_index()]; }

 private:
  // 64 bytes, the cache line of the x86-64 and ARMv8 cores this runs on.
  struct alignas(64) Slot {
    T value;
  };
  std::vector<Slot> slots_;
};

/// Appends every thread's list to out, in thread order (the order the threads' static ranges
/// come in, so the result does not depend on the timing), emptying the lists.
template <class List>
void append_and_clear(PerThread<List>& lists, List& out) {
  for (int t = 0; t < lists.size(); ++t) {
    out.insert(out.end(), lists[t].begin(), lists[t].end());
    lists[t].clear();
  }
}

}  // namespace topstoc
