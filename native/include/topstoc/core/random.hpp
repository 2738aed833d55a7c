// Counter-based random numbers: the value for (seed, index) depends on nothing else, so serial
// and parallel code draw the same numbers and results are reproducible on every platform.
#pragma once

#include <cstdint>

namespace topstoc {

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
inline uint64_t mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Uniform double in the open interval (0, 1) for (seed, stream, index).
inline double uniform01(uint64_t seed, uint64_t stream, uint64_t index) {
  const uint64_t h = mix64(mix64(seed ^ (stream * 0xD1B54A32D192ED03ull)) ^ index);
  return (double(h >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

}  // namespace topstoc
