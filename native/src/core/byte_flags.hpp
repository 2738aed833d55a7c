// Flags stored one per byte (0 or 1), read eight at a time: scans over a few percent set skip
// the zero words, and walk the set ones by bit instead of testing each byte (which
// mispredicted on such sparse arrays).
#pragma once

#include <cstdint>
#include <cstring>

namespace topstoc {

/// The 8 flags at `bytes` as one word.
inline uint64_t flag_word(const uint8_t* bytes) {
  uint64_t word;
  std::memcpy(&word, bytes, 8);
  return word;
}

/// The flags of a word (bytes 0 or 1) as the bits of one byte: byte i -> bit i.
inline uint32_t flag_bits(uint64_t word) {
  return uint32_t(((word & 0x0101010101010101ull) * 0x0102040810204080ull) >> 56);
}

/// How many of a word's flags (bytes 0 or 1) are set: the bytes summed into the top one by a
/// multiply (a portable build has no popcount instruction and calls a library function).
inline uint32_t flag_count(uint64_t word) { return uint32_t((word * 0x0101010101010101ull) >> 56); }

}  // namespace topstoc
