// What GCC and Clang offer as builtins and POSIX as macros, for every compiler the engine is
// built with (GCC, Clang, mingw-w64, MSVC): bit scans, a prefetch hint and pi.
#pragma once

#include <cstdint>

#if defined(_MSC_VER) && !defined(__clang__)
#include <intrin.h>
#include <xmmintrin.h>
#endif

namespace topstoc {

constexpr double kPi = 3.14159265358979323846;  // M_PI is POSIX, not standard C++

/// Index of the lowest set bit of word (word must not be 0).
inline int lowest_bit(uint64_t word) {
#if defined(_MSC_VER) && !defined(__clang__)
  unsigned long index;
  _BitScanForward64(&index, word);
  return int(index);
#else
  return __builtin_ctzll(word);
#endif
}

/// Index of the highest set bit of word (word must not be 0).
inline int highest_bit(uint64_t word) {
#if defined(_MSC_VER) && !defined(__clang__)
  unsigned long index;
  _BitScanReverse64(&index, word);
  return int(index);
#else
  return 63 - __builtin_clzll(word);
#endif
}

/// Asks the processor to fetch the cache line of p for reading (a hint; no effect on results).
inline void prefetch(const void* p) {
#if defined(_MSC_VER) && !defined(__clang__)
  _mm_prefetch(static_cast<const char*>(p), _MM_HINT_T0);
#else
  __builtin_prefetch(p);
#endif
}

}  // namespace topstoc
