// A set of ids in [0, n) kept as one bit each, read back in increasing order.
//
// Putting a few ten thousand ids scattered over a mesh in order this way costs a tenth of
// sorting them, and a later walk over the mesh's arrays in that order reads them in order
// instead of at random (sampling's draw, the partition check's re-tested faces).
#pragma once

#include <cstdint>
#include <vector>

#include "portable.hpp"
namespace topstoc {

class IdBits {
 public:
  explicit IdBits(int64_t n) : words_((size_t(n) + 63) / 64, 0) {}
  /// Adds id; false when it was in the set already.
  bool insert(int32_t id) {
    uint64_t& word = words_[size_t(id) >> 6];
    const uint64_t bit = uint64_t(1) << (id & 63);
    const bool fresh = !(word & bit);
    word |= bit;
    return fresh;
  }
  /// Calls visit(id) for every id in the set, in increasing order.
  template <class Visit>
  void for_each(Visit visit) const {
    for (size_t w = 0; w < words_.size(); ++w)
      for (uint64_t word = words_[w]; word; word &= word - 1) visit(int32_t(64 * w + size_t(lowest_bit(word))));
  }

 private:
  std::vector<uint64_t> words_;
};

}  // namespace topstoc
