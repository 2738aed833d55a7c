// Ids in ascending order of a value computed where read (the importance table's q), exactly as a
// stable sort puts them, holding two id arrays and two bytes an id instead of the values.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <vector>

#include "core/counting_sort.hpp"
#include "core/portable.hpp"
#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace detail {

// Stable LSD radix sort of ids[begin, end), whose key_of(id) >> below are all the same: by the
// keys' bits below `below`, 16 at a time, through other[begin, end).
template <class Key>
void sort_low_bits(std::vector<int32_t>& ids, std::vector<int32_t>& other, size_t begin, size_t end, int below,
                   const Key& key_of) {
  constexpr int kDigit = 16;
  constexpr uint64_t kMask = (uint64_t(1) << kDigit) - 1;
  uint64_t any = 0, all = ~uint64_t(0);
  for (size_t i = begin; i < end; ++i) {
    const uint64_t key = key_of(ids[i]);
    any |= key, all &= key;
  }
  std::vector<int32_t> offsets;
  for (int shift = 0; shift < below; shift += kDigit) {
    if ((((any ^ all) >> shift) & kMask) == 0) continue;  // the same digit everywhere
    const int32_t* from = ids.data() + begin;
    int32_t* to = other.data() + begin;
    auto digit = [&](int64_t i) { return int32_t((key_of(from[i]) >> shift) & kMask); };
    stable_counting_sort(int64_t(end - begin), int32_t(kMask + 1), digit,
                         [&](int64_t i, int32_t at) { to[at] = from[i]; }, offsets);
    std::copy(to, to + (end - begin), ids.data() + begin);
  }
}

// Sorts each bucket [offsets[b], offsets[b + 1]) of ids by next_bits and position, then runs of
// equal next_bits by key_of (when `exact` is false: the carried bits are not the whole key).
// Buckets over `largest` are left as they are.
template <class Key>
void sort_buckets(std::vector<int32_t>& ids, std::vector<int32_t>& other, const std::vector<int32_t>& offsets,
                  const std::vector<uint16_t>& next_bits, bool exact, size_t largest, const Key& key_of) {
  struct Tied {
    uint64_t key;
    uint32_t at;
    bool operator<(const Tied& o) const { return key < o.key || (key == o.key && at < o.at); }
  };
  std::vector<std::vector<uint64_t>> orders(max_threads());  // per thread: next bits << 32 | position
  std::vector<std::vector<Tied>> ties(max_threads());
  const int64_t buckets = int64_t(offsets.size()) - 1;
  parallel_for_dynamic(0, buckets, 256, 4096, [&](int64_t b) {
    const size_t begin = offsets[b], size = size_t(offsets[b + 1]) - begin;
    if (size < 2 || size > largest) return;
    auto& order = orders[thread_index()];
    order.resize(size);
    for (size_t i = 0; i < size; ++i) order[i] = uint64_t(next_bits[begin + i]) << 32 | i;
    std::sort(order.begin(), order.end());
    for (size_t i = 0, j = 0; !exact && i < size; i = j) {
      for (j = i + 1; j < size && order[j] >> 32 == order[i] >> 32;) ++j;
      if (j - i < 2) continue;
      auto& tied = ties[thread_index()];
      tied.clear();
      for (size_t k = i; k < j; ++k) tied.push_back({key_of(ids[begin + uint32_t(order[k])]), uint32_t(order[k])});
      std::sort(tied.begin(), tied.end());
      for (size_t k = i; k < j; ++k) order[k] = tied[k - i].at;
    }
    for (size_t i = 0; i < size; ++i) other[begin + i] = ids[begin + uint32_t(order[i])];
    std::copy(other.begin() + begin, other.begin() + begin + size, ids.begin() + begin);
  });
}

}  // namespace detail

/// Puts ids in ascending order of value(id) (equal values keep their order), exactly as a stable
/// sort would. Non-negative doubles order like their bit patterns: one counting pass, reading the
/// values in the ids' order (the importance table's come in vertex order), puts the ids in 2^16
/// buckets that split the bits' range evenly, each id with the next 16 bits of its value beside
/// it; each bucket is then sorted on those, reading a value at random only where two ids of a
/// bucket carry the same bits (an LSD radix sort of the ids read every value at random in each
/// of its four passes). A bucket too large for a small scratch (many equal values) takes that
/// LSD radix sort.
template <class Value>
void sort_ascending(std::vector<int32_t>& ids, const Value& value) {
  auto bits_of = [&](int32_t v) {
    const double x = value(v);
    uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    return bits;
  };
  constexpr uint64_t kInfinityBits = uint64_t(0x7FF) << 52;  // above: NaN or the sign bit
  uint64_t least = ~uint64_t(0), most = 0;
  bool plain = true;  // no negative number, -0 or NaN
  for (int32_t v : ids) {
    const uint64_t bits = bits_of(v);
    least = std::min(least, bits), most = std::max(most, bits);
    plain &= bits <= kInfinityBits;
  }
  if (!plain) {
    std::vector<double> values(ids.size());
    for (size_t i = 0; i < ids.size(); ++i) values[i] = value(ids[i]);
    std::vector<size_t> order(values.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return values[a] < values[b]; });
    std::vector<int32_t> sorted_ids(ids.size());
    for (size_t i = 0; i < order.size(); ++i) sorted_ids[i] = ids[order[i]];
    ids.swap(sorted_ids);
    return;
  }
  if (least == most) return;  // all equal
  // (A window of the bits themselves would put a few binades of q in a few dozen buckets.)
  constexpr int kDigit = 16;
  const int low = std::max(0, highest_bit(most - least) + 1 - kDigit);  // the offset's bits below the bucket
  const int carried = std::min(low, kDigit);
  auto offset_of = [&](int32_t v) { return bits_of(v) - least; };
  std::vector<int32_t> other(ids.size()), offsets;
  std::vector<uint16_t> next_bits(ids.size());
  const int32_t* from = ids.data();
  stable_counting_sort(
      int64_t(ids.size()), int32_t(((most - least) >> low) + 1),
      [&](int64_t i) { return int32_t(offset_of(from[i]) >> low); },
      [&](int64_t i, int32_t at) {
        other[at] = from[i];
        next_bits[at] = uint16_t(offset_of(from[i]) >> (low - carried));
      },
      offsets);
  ids.swap(other);
  if (low == 0) return;
  constexpr size_t kScratch = size_t(1) << 14;
  detail::sort_buckets(ids, other, offsets, next_bits, low == carried, kScratch, offset_of);
  for (size_t b = 0; b + 1 < offsets.size(); ++b)
    if (size_t(offsets[b + 1]) - offsets[b] > kScratch)
      detail::sort_low_bits(ids, other, offsets[b], offsets[b + 1], low, offset_of);
}

}  // namespace topstoc
