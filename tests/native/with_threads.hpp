// Test helper: runs f with the calling thread's team size set to `threads`, restored after
// (also when f throws), and returns what f returns.
#pragma once

#include "topstoc/core/parallel.hpp"

template <class F>
auto with_threads(int threads, F f) {
  struct Restore {
    int before;
    ~Restore() { topstoc::set_max_threads(before); }
  } restore{topstoc::max_threads()};
  topstoc::set_max_threads(threads);
  return f();
}
