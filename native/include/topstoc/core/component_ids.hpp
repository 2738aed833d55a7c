// Connected component of each vertex (-1 for an isolated vertex), stored in the fewest bytes that
// hold the mesh's ids: none for one component without isolated vertices, else 1, 2 or 4 bytes a
// vertex (the most negative value of the width standing for -1). Read like the int32 table it
// replaces (operator[], size()), which was 2 bytes a triangle of every prepared mesh.
#pragma once

#include <cstdint>
#include <cstring>

#include "topstoc/core/buffer.hpp"

namespace topstoc {

class ComponentIds {
 public:
  using value_type = int32_t;

  /// From each vertex's component (-1 for none); `components` is one more than the largest.
  void assign(const Buffer<int32_t>& ids, int32_t components) {
    size_ = ids.size();
    bool isolated = false;
    for (const int32_t c : ids) isolated |= c < 0;
    width_ = (components <= 1 && !isolated) ? 0 : components < INT8_MAX ? 1 : components < INT16_MAX ? 2 : 4;
    Buffer<uint8_t>(size_ * width_).swap(bytes_);
    for (size_t v = 0; v < size_ && width_ > 0; ++v) {
      if (width_ == 1) bytes_[v] = uint8_t(int8_t(ids[v]));
      else if (width_ == 2) store(v, int16_t(ids[v]));
      else store(v, ids[v]);
    }
  }

  int32_t operator[](size_t v) const {
    switch (width_) {
      case 0: return 0;
      case 1: return int8_t(bytes_[v]);
      case 2: return load<int16_t>(v);
      default: return load<int32_t>(v);
    }
  }
  size_t size() const { return size_; }
  /// Bytes a vertex (0, 1, 2 or 4): how the ids are held, for tests.
  int width() const { return width_; }

 private:
  template <class T>
  void store(size_t v, T value) { std::memcpy(bytes_.data() + sizeof(T) * v, &value, sizeof(T)); }
  template <class T>
  T load(size_t v) const {
    T value;
    std::memcpy(&value, bytes_.data() + sizeof(T) * v, sizeof(T));
    return value;
  }

  Buffer<uint8_t> bytes_;
  size_t size_ = 0;
  int width_ = 0;
};

}  // namespace topstoc
