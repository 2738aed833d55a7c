// Big arrays filled in parallel: std::vector whose new elements are left uninitialised.
//
// A prepared million-triangle mesh is about 250 MB of arrays. std::vector zero-fills what it
// allocates on the calling thread, so every page was faulted in (and zeroed twice, by the kernel
// and by the fill) on one core before the parallel loops that compute the values ran. With
// this allocator the loops that write the values are the first to touch the pages, on all
// threads. Elements not written explicitly hold garbage: fill what a loop skips.
#pragma once

#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace topstoc {

template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  using std::allocator<T>::allocator;
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  /// Default-initialisation (nothing, for numbers) instead of value-initialisation (zero).
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
using Buffer = std::vector<T, UninitialisedAllocator<T>>;

}  // namespace topstoc
