#include "topstoc/core/digest.hpp"
#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "topstoc/core/random.hpp"

namespace topstoc {

namespace {

constexpr size_t kBlockBytes = size_t(1) << 20;
constexpr uint64_t kMultiplier[4] = {0x9E3779B97F4A7C15ull, 0xC2B2AE3D27D4EB4Full, 0x165667B19E3779F9ull,
                                     0xD6E8FEB86659FD93ull};

inline uint64_t rotate(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

// One block: four lanes, each step a bijection of the lane for a given word (xor, odd multiply,
// rotate), so changing any one word changes its lane; the lanes are mixed at the end.
std::array<uint64_t, 2> block_digest(const unsigned char* p, size_t bytes, uint64_t index) {
  uint64_t lane[4] = {mix64(index), mix64(index + 1), mix64(index + 2), mix64(index + 3)};
  size_t at = 0;
  for (; at + 32 <= bytes; at += 32)
    for (int l = 0; l < 4; ++l) {
      uint64_t w;
      std::memcpy(&w, p + at + 8 * l, 8);
      lane[l] = rotate((lane[l] ^ w) * kMultiplier[l], 29) * 0xFF51AFD7ED558CCDull;
    }
  unsigned char tail[32] = {};
  std::memcpy(tail, p + at, bytes - at);
  for (int l = 0; l < 4; ++l) {
    uint64_t w;
    std::memcpy(&w, tail + 8 * l, 8);
    lane[l] = rotate((lane[l] ^ w) * kMultiplier[l], 29) * 0xFF51AFD7ED558CCDull;
  }
  const uint64_t a = mix64(lane[0] ^ mix64(lane[1] ^ bytes)), b = mix64(lane[2] ^ mix64(lane[3] ^ ~uint64_t(bytes)));
  return {mix64(a ^ rotate(b, 17)), mix64(b ^ rotate(a, 41))};
}

}  // namespace

std::array<uint64_t, 2> content_digest(const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  const int64_t blocks = int64_t((bytes + kBlockBytes - 1) / kBlockBytes);
  std::vector<std::array<uint64_t, 2>> digests(blocks);
  parallel_for(0, blocks, 8, [&](int64_t b) {
    const size_t begin = size_t(b) * kBlockBytes;
    digests[b] = block_digest(p + begin, std::min(kBlockBytes, bytes - begin), uint64_t(b) * 4);
  });
  std::array<uint64_t, 2> h = {mix64(bytes), mix64(~uint64_t(bytes))};
  for (const auto& d : digests) {
    h[0] = mix64(rotate(h[0], 23) ^ d[0]);
    h[1] = mix64(rotate(h[1], 37) ^ d[1] ^ h[0]);
  }
  return h;
}

}  // namespace topstoc
