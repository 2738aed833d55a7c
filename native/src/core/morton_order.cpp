#include "core/morton_order.hpp"

#include <algorithm>

#include "topstoc/core/parallel.hpp"

namespace topstoc {

namespace {

// Spreads the low 10 bits of x so that they occupy every third bit.
uint32_t spread_bits(uint32_t x) {
  x &= 0x3ff;
  x = (x | x << 16) & 0x30000ff;
  x = (x | x << 8) & 0x300f00f;
  x = (x | x << 4) & 0x30c30c3;
  x = (x | x << 2) & 0x9249249;
  return x;
}

}  // namespace

// A radix sort of (key, id) pairs.
std::vector<int32_t> morton_order(const double* positions, int32_t n) {
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int32_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      const double x = positions[3 * size_t(v) + k];
      lo[k] = v ? std::min(lo[k], x) : x;
      hi[k] = v ? std::max(hi[k], x) : x;
    }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  std::vector<uint64_t> keyed(n), scratch(n);
  parallel_for(0, n, kParallelMin, [&](int32_t v) {
    uint32_t key = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = (positions[3 * size_t(v) + k] - lo[k]) / extent;
      key |= spread_bits(uint32_t(std::clamp(t, 0.0, 1.0) * 1023.0)) << k;
    }
    keyed[v] = (uint64_t(key) << 32) | uint32_t(v);
  });
  // Least significant digit first, 3 passes of 10 bits over the 30-bit key (stable).
  for (int shift = 32; shift < 62; shift += 10) {
    std::vector<int32_t> count(1025, 0);
    for (uint64_t x : keyed) ++count[((x >> shift) & 1023) + 1];
    for (int i = 0; i < 1024; ++i) count[i + 1] += count[i];
    for (uint64_t x : keyed) scratch[count[(x >> shift) & 1023]++] = x;
    keyed.swap(scratch);
  }
  std::vector<int32_t> order(n);
  for (int32_t i = 0; i < n; ++i) order[i] = int32_t(uint32_t(keyed[i]));
  return order;
}

}  // namespace topstoc
