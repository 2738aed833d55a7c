// Stable counting sort on all threads: the items 0..count-1 go to the buckets key(i) in
// [0, buckets), each bucket in item order, exactly where a serial counting sort puts them. Each
// thread counts and then places one contiguous run of the items, and a bucket's slots are handed
// out run by run, so the result never depends on the number of threads.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "topstoc/core/parallel.hpp"

namespace topstoc {

/// place(i, position) receives each item's position in the sorted order; offsets (buckets + 1
/// entries) receives the first position of every bucket and, last, the count.
template <class Key, class Place, class Offsets>
void stable_counting_sort(int64_t count, int32_t buckets, Key key, Place place, Offsets& offsets) {
  if (count > INT32_MAX) throw std::invalid_argument("mesh is too large: more than 2^31 incidences");
  const int team = count >= kParallelMin ? max_threads() : 1;
  offsets.resize(size_t(buckets) + 1);
  if (team == 1) {  // the plain serial sort: no per-thread tables
    std::fill(offsets.begin(), offsets.end(), 0);
    for (int64_t i = 0; i < count; ++i) ++offsets[key(i) + 1];
    for (int32_t b = 0; b < buckets; ++b) offsets[b + 1] += offsets[b];
    std::vector<int32_t> next(offsets.begin(), offsets.end() - 1);  // (serial: small meshes)
    for (int64_t i = 0; i < count; ++i) place(i, next[key(i)]++);
    return;
  }
  std::unique_ptr<int32_t[]> cursors;  // per thread and bucket: counts, then the next position
  // Rows a whole number of cache lines long plus one: with few buckets (distances in a flood
  // update) the threads' rows would otherwise share lines that every item writes.
  const size_t row = (size_t(buckets) + 15) / 16 * 16 + 16;
  std::vector<int64_t> range_start;    // per thread: first position of its range of buckets
  parallel_region(team, [&](Team& t) {
    // The team may come out smaller than asked; the runs follow the team actually running.
    const int threads = t.size(), me = t.index();
    t.single([&] {
      cursors.reset(new int32_t[size_t(threads) * row]);  // each thread clears its own row
      range_start.assign(threads + 1, 0);
    });
    int32_t* mine = cursors.get() + size_t(me) * row;
    std::fill(mine, mine + buckets, 0);
    const int64_t begin = count * me / threads, end = count * (me + 1) / threads;
    for (int64_t i = begin; i < end; ++i) ++mine[key(i)];
    t.barrier();
    // Each thread totals one range of buckets; the ranges' starts follow in order.
    const int32_t first = int32_t(int64_t(buckets) * me / threads), last = int32_t(int64_t(buckets) * (me + 1) / threads);
    int64_t total = 0;
    for (int32_t b = first; b < last; ++b)
      for (int r = 0; r < threads; ++r) total += cursors[size_t(r) * row + b];
    range_start[me + 1] = total;
    t.barrier();
    t.single([&] {
      for (int r = 0; r < threads; ++r) range_start[r + 1] += range_start[r];
    });
    int64_t at = range_start[me];
    for (int32_t b = first; b < last; ++b) {
      offsets[b] = int32_t(at);
      for (int r = 0; r < threads; ++r) {
        const int32_t n = cursors[size_t(r) * row + b];
        cursors[size_t(r) * row + b] = int32_t(at);
        at += n;
      }
    }
    t.barrier();
    for (int64_t i = begin; i < end; ++i) place(i, mine[key(i)]++);
  });
  offsets[buckets] = int32_t(count);
}

}  // namespace topstoc
