// A byte flag per vertex (0 or 1) held as nothing when every vertex's is set: the manifold
// flags of a mesh without a non-manifold vertex (half a byte a triangle of every prepared mesh).
// Read like the byte table it replaces (operator[], size()).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>

#include "topstoc/core/buffer.hpp"

namespace topstoc {

class VertexFlags {
 public:
  using value_type = uint8_t;

  /// Takes the flags; keeps none of them when all are set.
  void assign(Buffer<uint8_t>&& flags) {
    size_ = flags.size();
    bool all_set = true;
    for (const uint8_t flag : flags) all_set &= flag != 0;
    if (all_set) Buffer<uint8_t>().swap(bytes_);
    else bytes_ = std::move(flags);
  }

  uint8_t operator[](size_t v) const { return bytes_.empty() ? uint8_t(1) : bytes_[v]; }
  size_t size() const { return size_; }
  /// Whether the flags are held (false: every one is set).
  bool held() const { return !bytes_.empty(); }

 private:
  Buffer<uint8_t> bytes_;
  size_t size_ = 0;
};

}  // namespace topstoc
