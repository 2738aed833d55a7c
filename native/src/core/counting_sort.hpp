// Stable counting sort on all threads: the items 0..count-1 go to the buckets key(i) in
// [0, buckets), each bucket in item order, exactly where a serial counting sort puts them. Each
// thread counts and then places one contiguous run of the items, and a bucket's slots are handed
// out run by run, so the result never depends on the number of threads.
#pragma once

#include <omp.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "topstoc/core/parallel.hpp"

namespace topstoc {

/// place(i, position) receives each item's position in the sorted order; offsets (buckets + 1
/// entries) receives the first position of every bucket and, last, the count.
template <class Key, class Place>
void stable_counting_sort(int64_t count, int32_t buckets, Key key, Place place, std::vector<int32_t>& offsets) {
  if (count > INT32_MAX) throw std::invalid_argument("mesh is too large: more than 2^31 incidences");
  const int team = count >= kParallelMin ? omp_get_max_threads() : 1;
  std::vector<int32_t> cursors;  // per thread and bucket: counts, then the next position
  offsets.resize(size_t(buckets) + 1);
#pragma omp parallel num_threads(team)
  {
    // The team may come out smaller than asked; the runs follow the team actually running.
    const int threads = omp_get_num_threads(), me = omp_get_thread_num();
#pragma omp single
    cursors.assign(size_t(threads) * buckets, 0);
    const int64_t begin = count * me / threads, end = count * (me + 1) / threads;
    int32_t* mine = cursors.data() + size_t(me) * buckets;
    for (int64_t i = begin; i < end; ++i) ++mine[key(i)];
#pragma omp barrier
#pragma omp single
    {
      int32_t sum = 0;
      for (int32_t b = 0; b < buckets; ++b) {
        offsets[b] = sum;
        for (int t = 0; t < threads; ++t) {
          const int32_t n = cursors[size_t(t) * buckets + b];
          cursors[size_t(t) * buckets + b] = sum;
          sum += n;
        }
      }
      offsets[buckets] = sum;
    }
    for (int64_t i = begin; i < end; ++i) place(i, mine[key(i)]++);
  }
}

}  // namespace topstoc
