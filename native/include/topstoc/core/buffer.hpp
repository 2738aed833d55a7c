// Big arrays filled in parallel: std::vector whose new elements are left uninitialised.
//
// A prepared million-triangle mesh is about 250 MB of arrays. std::vector zero-fills what it
// allocates on the calling thread, so every page was faulted in (and zeroed twice, by the kernel
// and by the fill) on one core before the parallel loops that compute the values ran. With
// this allocator the loops that write the values are the first to touch the pages, on all
// threads. Elements not written explicitly hold garbage: fill what a loop skips.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

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
#if defined(__linux__)
  // Big buffers map their own pages and unmap them when freed (Linux): through malloc, glibc
  // raises its mapping threshold to the size of each big block freed (up to 32 MB), after which
  // blocks of a few megabytes come from its heap and stay resident once freed (on a 2M-triangle
  // mesh the prepared mesh then held a fifth more memory than its arrays).
  static constexpr size_t kMapped = size_t(1) << 20;
  T* allocate(size_t n) {
    if (n * sizeof(T) < kMapped) return std::allocator<T>::allocate(n);
    if (n > SIZE_MAX / sizeof(T)) throw std::bad_array_new_length();
    void* p = mmap(nullptr, n * sizeof(T), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) noexcept {
    if (n * sizeof(T) < kMapped) return std::allocator<T>::deallocate(p, n);
    munmap(p, n * sizeof(T));
  }
#endif
};

template <class T>
using Buffer = std::vector<T, UninitialisedAllocator<T>>;

/// Gives the whole pages past a buffer's end back to the system (Linux; elsewhere nothing): a
/// buffer shrunk with resize() keeps its capacity, and its unused tail then costs address space
/// only. Those pages read as zero if the buffer grows again.
template <class T>
void release_unused(Buffer<T>& buffer) {
#if defined(__linux__)
  const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
  const uintptr_t first = (uintptr_t(buffer.data() + buffer.size()) + page - 1) / page * page;
  const uintptr_t last = uintptr_t(buffer.data() + buffer.capacity()) / page * page;
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
#else
  (void)buffer;
#endif
}

/// Gives the whole pages of buffer[begin, end) back to the system (Linux, buffers that map their
/// own pages; elsewhere nothing): entries read for the last time while the rest is still in use
/// (a pass over vertex slices). Those pages read as zero afterwards.
template <class T>
void release_range(Buffer<T>& buffer, size_t begin, size_t end) {
#if defined(__linux__)
  if (buffer.capacity() * sizeof(T) < UninitialisedAllocator<T>::kMapped || end <= begin) return;
  const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
  const uintptr_t first = (uintptr_t(buffer.data() + begin) + page - 1) / page * page;
  const uintptr_t last = uintptr_t(buffer.data() + end) / page * page;
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
#else
  (void)buffer, (void)begin, (void)end;
#endif
}

/// Gives the heap's free pages back to the system (glibc; elsewhere nothing) after a stage that
/// freed about `freed` bytes: std::vector's blocks of a few megabytes come from glibc's heap once
/// its mapping threshold has risen, and stay resident once freed, under the next stage's working
/// set (2 bytes a triangle of a 2M-triangle decimation's peak). Under 1 MB, nothing is done.
inline void release_freed_heap(size_t freed) {
#if defined(__GLIBC__)
  if (freed >= (size_t(1) << 20)) malloc_trim(0);
#else
  (void)freed;
#endif
}

}  // namespace topstoc
