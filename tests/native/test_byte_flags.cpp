// Flags stored one per byte, read eight at a time: every one of the 256 patterns of eight 0/1
// bytes against the flags counted and listed byte by byte.
#include <doctest/doctest.h>

#include <cstdint>

#include "core/byte_flags.hpp"

TEST_CASE("flag words give the set bytes as bits and their count") {
  for (uint32_t pattern = 0; pattern < 256; ++pattern) {
    uint8_t bytes[8];
    uint32_t count = 0;
    for (int i = 0; i < 8; ++i) count += bytes[i] = uint8_t((pattern >> i) & 1);
    const uint64_t word = topstoc::flag_word(bytes);
    CHECK(topstoc::flag_bits(word) == pattern);
    CHECK(topstoc::flag_count(word) == count);
  }
}
