// Ids 0..n-1 in ascending order of a 63-bit key, ties by id (what a stable sort of the ids by
// key gives), moving one 64-bit word an id: the id packed under its key's top bits.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/counting_sort.hpp"
#include "topstoc/core/buffer.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

/// The bits an id below n needs (at least one).
inline int id_bits_for(int64_t n) {
  int bits = 1;
  while ((int64_t(1) << bits) < n) ++bits;
  return bits;
}

/// Puts a run of (key, id) items, in id order and equal in the key's bits above `bits`, in order
/// of key then id: a stable radix sort over the low bits, linear however long the run (a far
/// outlier leaves nearly every vertex in one).
template <class Item>
void sort_run_by_low_bits(std::vector<Item>& run, std::vector<Item>& scratch, int bits) {
  constexpr int kDigit = 11;
  std::vector<int32_t> next(size_t(1) << kDigit);
  scratch.resize(run.size());
  for (int shift = 0; shift < bits; shift += kDigit) {
    const uint64_t mask = (uint64_t(1) << std::min(kDigit, bits - shift)) - 1;
    std::fill(next.begin(), next.end(), 0);
    for (const Item& item : run) ++next[(item.first >> shift) & mask];
    int32_t at = 0;
    for (int32_t& slot : next) at += std::exchange(slot, at);
    for (const Item& item : run) scratch[next[(item.first >> shift) & mask]++] = item;
    run.swap(scratch);
  }
}

/// Sorts the ids 0..n-1 by key_of(id) (keys below 2^63), ties by id; out[i] & ((1 << id_bits_for(n))
/// - 1) is the i-th id. Each id travels in one word under its key's top 64 - b bits (b the bits an
/// id needs): a stable LSD radix sort of about 11 bits a pass moves 8 bytes an id over those
/// bits (a key beside its id would be 12 bytes over 63 bits), and ids whose words tie on the
/// key's bits are then put in order of their whole keys (key_of read again), which on a Z-order
/// of a surface's vertices are a few. after_pass(done) follows the keys and each pass with the share of passes done (a
/// cancel point).
template <class KeyOf, class AfterPass>
void sort_ids_by_key(int32_t n, const KeyOf& key_of, Buffer<uint64_t>& out, const AfterPass& after_pass) {
  const int id_bits = id_bits_for(n), top_bits = 64 - id_bits;
  const uint64_t id_mask = (uint64_t(1) << id_bits) - 1;
  out.resize(n);
  parallel_for(0, n, kParallelMin, [&](int32_t v) { out[v] = (key_of(v) >> (id_bits - 1)) << id_bits | uint32_t(v); });
  after_pass(0.0);
  {
    const int passes = (top_bits + 10) / 11, digit = (top_bits + passes - 1) / passes;
    const uint64_t mask = (uint64_t(1) << digit) - 1;
    Buffer<uint64_t> other(n);
    Buffer<int32_t> ignored;
    for (int pass = 0; pass < passes; ++pass) {
      const int shift = id_bits + pass * digit;
      const uint64_t* from = out.data();
      uint64_t* to = other.data();
      stable_counting_sort(
          n, int32_t(mask + 1), [&](int64_t i) { return int32_t((from[i] >> shift) & mask); },
          [&](int64_t i, int32_t at) { to[at] = from[i]; }, ignored);
      out.swap(other);
      after_pass(double(pass + 1) / passes);
    }
  }
  // Runs of words equal above the ids hold their ids ascending; each goes in order of whole key
  // then id. The runs' starts are marked first (a bit an id), so that each run is read and
  // written by the one block where it starts.
  constexpr int64_t kBlock = 1 << 16;  // a multiple of 64: a block's bits are its own words
  constexpr size_t kLongRun = 4096;     // longer runs are radix sorted (linear), shorter compared
  const int64_t blocks = (int64_t(n) + kBlock - 1) / kBlock;
  auto top = [&](int64_t i) { return out[i] >> id_bits; };
  std::vector<uint64_t> starts((size_t(n) + 63) / 64, 0);
  auto starts_run = [&](int64_t i) { return (starts[size_t(i) >> 6] >> (i & 63)) & 1; };
  parallel_for(0, blocks, 2, [&](int64_t b) {
    for (int64_t i = b * kBlock, end = std::min<int64_t>(n, (b + 1) * kBlock); i < end; ++i)
      if (i == 0 || top(i) != top(i - 1)) starts[size_t(i) >> 6] |= uint64_t(1) << (i & 63);
  });
  parallel_for_dynamic(0, blocks, 1, 2, [&](int64_t b) {
    std::vector<std::pair<uint64_t, uint32_t>> run, scratch;
    for (int64_t i = b * kBlock, end = std::min<int64_t>(n, (b + 1) * kBlock); i < end; ++i) {
      if (!starts_run(i)) continue;
      int64_t j = i + 1;
      while (j < n && !starts_run(j)) ++j;
      if (j - i < 2) continue;
      run.clear();
      for (int64_t k = i; k < j; ++k) run.push_back({key_of(int32_t(out[k] & id_mask)), uint32_t(out[k] & id_mask)});
      if (std::is_sorted(run.begin(), run.end())) continue;  // equal keys (far outliers) keep the id order
      if (run.size() > kLongRun) sort_run_by_low_bits(run, scratch, id_bits - 1);
      else std::sort(run.begin(), run.end());
      const uint64_t high = top(i) << id_bits;
      for (int64_t k = i; k < j; ++k) out[k] = high | run[k - i].second;
    }
  });
}

}  // namespace topstoc
