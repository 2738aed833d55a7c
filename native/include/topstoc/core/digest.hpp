// Content digest of a byte buffer, for caches that must notice any change of a big array (the
// add-on keys its prepared meshes by the positions and triangles it reads).
//
// Not cryptographic: 128 bits that change with any accidental change. Blocks of 1 MiB are
// digested independently (on all threads) and folded in order, so the value does not depend on
// the number of threads. Several times faster than blake2b, which also held the interpreter
// lock while it ran.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace topstoc {

std::array<uint64_t, 2> content_digest(const void* data, size_t bytes);

}  // namespace topstoc
