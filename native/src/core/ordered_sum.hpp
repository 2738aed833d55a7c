// Parallel sums whose bits do not depend on the number of threads.
//
// Floating-point addition is not associative: an OpenMP reduction adds each thread's share and
// then the shares, so the last bits of its result depend on how many threads ran (and a result
// that feeds a decision can then differ between a laptop and a farm node). Here the terms are
// cut into fixed blocks of kSumBlock, each block is summed in order by whichever thread takes
// it, and the block sums are added in block order on one thread: the same additions in the
// same order for any thread count, serial included.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "topstoc/core/parallel.hpp"

namespace topstoc {

constexpr int64_t kSumBlock = 4096;

/// Reduces terms 0..n-1: accumulate(partial, i) adds term i to its block's Partial (value
/// initialised), combine(total, partial) adds the block partials in block order.
template <class Partial, class Accumulate, class Combine>
Partial ordered_reduce(int64_t n, Accumulate accumulate, Combine combine) {
  const int64_t blocks = (n + kSumBlock - 1) / kSumBlock;
  std::vector<Partial> partial(size_t(std::max<int64_t>(blocks, 0)), Partial{});
  parallel_for(0, blocks, parallel_if(n >= kParallelMin), [&](int64_t b) {
    for (int64_t i = b * kSumBlock, end = std::min(n, (b + 1) * kSumBlock); i < end; ++i) accumulate(partial[b], i);
  });
  Partial total{};
  for (const Partial& p : partial) combine(total, p);
  return total;
}

/// Sum of term(i) for i in 0..n-1, the same to the bit for any thread count.
template <class Term>
double ordered_sum(int64_t n, Term term) {
  return ordered_reduce<double>(
      n, [&](double& sum, int64_t i) { sum += term(i); }, [](double& total, double part) { total += part; });
}

}  // namespace topstoc
