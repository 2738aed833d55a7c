// A least-significant-digit radix sort of items by an unsigned 64-bit `code` member: linear time
// for the vertex grid's order of the vertices by cell.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace topstoc {

/// Sorts items by their lowest `bits` bits of code, ties in their given order.
template <class Item>
void radix_sort(std::vector<Item>& items, int bits) {
  constexpr int kDigitBits = 11;  // the counts of one digit stay in cache
  constexpr uint64_t kMask = (uint64_t(1) << kDigitBits) - 1;
  if (items.size() < 2) return;
  std::vector<Item> other(items.size());
  std::vector<int64_t> count(kMask + 1);
  for (int shift = 0; shift < bits; shift += kDigitBits) {
    std::fill(count.begin(), count.end(), 0);
    for (const auto& item : items) ++count[(item.code >> shift) & kMask];
    if (count[(items.front().code >> shift) & kMask] == int64_t(items.size())) continue;  // one digit: no move
    int64_t sum = 0;
    for (auto& c : count) sum += std::exchange(c, sum);
    for (const auto& item : items) other[size_t(count[(item.code >> shift) & kMask]++)] = item;
    items.swap(other);
  }
}

}  // namespace topstoc
