// sort_ids_by_key (core/sort_by_key.hpp) puts ids exactly where std::stable_sort by key does:
// keys spread over 63 bits, keys equal in the bits carried beside the ids but not below them
// (runs put in order of their whole keys, some across the blocks that own them), many equal
// keys, one run of nearly every id, small counts; serial and on two threads.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "core/sort_by_key.hpp"
#include "with_threads.hpp"

using namespace topstoc;

namespace {

std::vector<int32_t> stable_order(const std::vector<uint64_t>& keys) {
  std::vector<int32_t> ids(keys.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = int32_t(i);
  std::stable_sort(ids.begin(), ids.end(), [&](int32_t a, int32_t b) { return keys[a] < keys[b]; });
  return ids;
}

void check_sorted(const std::vector<uint64_t>& keys) {
  const int32_t n = int32_t(keys.size());
  for (int threads : {1, 2}) {
    std::vector<double> passes;
    Buffer<uint64_t> out;
    with_threads(threads, [&] {
      sort_ids_by_key(n, [&](int32_t v) { return keys[v]; }, out, [&](double done) { passes.push_back(done); });
      return 0;
    });
    const uint64_t mask = (uint64_t(1) << id_bits_for(n)) - 1;
    std::vector<int32_t> ids(n);
    for (int32_t i = 0; i < n; ++i) ids[i] = int32_t(out[i] & mask);
    CHECK(ids == stable_order(keys));
    REQUIRE(!passes.empty());
    CHECK(passes.front() == 0.0);
    CHECK(passes.back() == 1.0);
  }
}

}  // namespace

TEST_CASE("sort_ids_by_key: the order of a stable sort by key") {
  std::mt19937_64 rng(11);
  const uint64_t k63 = (uint64_t(1) << 63) - 1;
  const int n = 300000;  // several blocks of the runs' pass, above the parallel minimum
  std::vector<uint64_t> keys(n);
  SUBCASE("spread over 63 bits, with repeats") {
    for (auto& k : keys) k = rng() & k63;
    for (int i = 0; i < n; i += 5) keys[i] = keys[(i * 37) % n];
  }
  SUBCASE("equal in the carried bits, different below them") {
    // 19 id bits: words carry the keys' top 45 bits; the low 18 bits decide within a run.
    for (int i = 0; i < n; ++i) keys[i] = ((rng() % 5000) << 40) | (rng() & 0x3ffff);
  }
  SUBCASE("long runs across blocks, equal keys inside them") {
    for (int i = 0; i < n; ++i) keys[i] = (uint64_t(i % 3) << 60) | (rng() % 64);
  }
  SUBCASE("one run of nearly every id (a far outlier)") {
    for (auto& k : keys) k = rng() % 100000;
    keys[n / 2] = k63;
  }
  SUBCASE("the largest and smallest keys") {
    for (int i = 0; i < n; ++i) keys[i] = (i % 2) ? k63 - (rng() % 3) : rng() % 3;
  }
  check_sorted(keys);
}

TEST_CASE("sort_ids_by_key: small counts") {
  std::mt19937_64 rng(5);
  for (int n : {1, 2, 3, 7, 64, 65, 1000}) {
    std::vector<uint64_t> keys(n);
    for (auto& k : keys) k = rng() % 50 << 50 | (rng() % 4);
    check_sorted(keys);
  }
}
