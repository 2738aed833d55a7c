// sort_ascending (core/sort_by_value.hpp) puts ids exactly where std::stable_sort by value does,
// on each of its paths: spread values (buckets sorted on the carried bits), values equal in the
// carried bits (read again), a narrow range (the counting pass alone), a bucket too large for
// the scratch (the radix sort), many equal values, infinities, negative values; serial and on
// two threads.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "core/sort_by_value.hpp"
#include "with_threads.hpp"

using namespace topstoc;

namespace {

std::vector<int32_t> stable_order(const std::vector<double>& values) {
  std::vector<int32_t> ids(values.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = int32_t(i);
  std::stable_sort(ids.begin(), ids.end(), [&](int32_t a, int32_t b) { return values[a] < values[b]; });
  return ids;
}

void check_sorted(const std::vector<double>& values) {
  for (int threads : {1, 2}) {
    std::vector<int32_t> ids(values.size());
    for (size_t i = 0; i < ids.size(); ++i) ids[i] = int32_t(i);
    with_threads(threads, [&] {
      sort_ascending(ids, [&](int32_t v) { return values[v]; });
      return 0;
    });
    CHECK(ids == stable_order(values));
  }
}

double with_low_bits(double x, uint64_t low_bits) {  // x with its lowest mantissa bits replaced
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = (bits & ~uint64_t(0xFFFF)) | (low_bits & 0xFFFF);
  std::memcpy(&x, &bits, sizeof bits);
  return x;
}

}  // namespace

TEST_CASE("sort_ascending: the order of a stable sort by value on every path") {
  std::mt19937_64 rng(7);
  const int n = 200000;  // above the counting sort's parallel minimum
  std::vector<double> values(n);
  SUBCASE("spread over a few binades, with repeats") {
    std::uniform_real_distribution<double> q(0.2, 6.0);
    for (auto& x : values) x = q(rng);
    for (int i = 0; i < n; i += 7) values[i] = values[(i * 31) % n];
  }
  SUBCASE("equal in the carried bits, different below them") {
    std::uniform_real_distribution<double> q(1.0, 1.5);
    for (auto& x : values) x = with_low_bits(q(rng) , rng());
    for (int i = 0; i < n; i += 2) values[i] = with_low_bits(values[i + 1], rng());
  }
  SUBCASE("a range the counting pass sorts alone") {
    for (auto& x : values) x = with_low_bits(2.0, rng() % 5000);
  }
  SUBCASE("a floor most values share, the rest spread (a bucket over the scratch)") {
    std::uniform_real_distribution<double> q(0.0, 1.0);
    for (auto& x : values) x = q(rng) < 0.6 ? 0.25 : 0.25 + q(rng);
  }
  SUBCASE("a dense cluster of distinct values (a large bucket, distinct below it)") {
    std::uniform_real_distribution<double> q(0.0, 1.0);
    for (auto& x : values) x = q(rng) < 0.5 ? std::nextafter(1.0, 2.0) + 1e-12 * q(rng) : 1.0 + 100 * q(rng);
  }
  SUBCASE("all equal") {
    std::fill(values.begin(), values.end(), 3.5);
  }
  SUBCASE("infinities among spread values") {
    std::uniform_real_distribution<double> q(0.0, 4.0);
    for (auto& x : values) x = q(rng) < 0.01 ? HUGE_VAL : q(rng);
  }
  SUBCASE("negative values and zeros") {
    std::uniform_real_distribution<double> q(-1.0, 1.0);
    for (auto& x : values) x = q(rng) < 0.1 ? 0.0 : q(rng);
  }
  check_sorted(values);
}
