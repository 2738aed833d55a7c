// Parallel sums in fixed blocks (core/ordered_sum.hpp): serial == parallel to the bit, on data
// where a plain per-thread reduction is not; and the two sums that used such a reduction
// (aspect_ratio_stats, Hausdorff's sample count) on a mesh large enough for the parallel path.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/ordered_sum.hpp"
#include "topstoc/core/parallel.hpp"
#include "with_threads.hpp"
#include "meshes.hpp"
#include "topstoc/core/quality.hpp"
#include "topstoc/distance/hausdorff.hpp"

using namespace topstoc;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Terms of very different magnitudes, so that the order of additions shows in the last bits.
std::vector<double> uneven_terms(int64_t n) {
  std::vector<double> x(n);
  uint64_t state = 12345;
  for (auto& v : x) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    v = std::ldexp(double(state >> 11) / double(1ull << 53), int((state >> 3) % 40) - 20);
  }
  return x;
}

// A jittered torus of 240,000 triangles (more than kParallelMin).
topstoc_test::Arrays big_torus() {
  auto a = topstoc_test::torus(400, 300);
  uint64_t state = 7;
  for (auto& p : a.positions) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    p += 1e-3 * (double(state >> 11) / double(1ull << 53) - 0.5);
  }
  return a;
}

}  // namespace

TEST_CASE("ordered_sum: fixed blocks in order, the same bits on 1, 2 and 3 threads") {
  const auto x = uneven_terms(3 * kParallelMin + 17);
  const int64_t n = int64_t(x.size());
  // The reference, written out: each block of kSumBlock in order, then the blocks in order.
  double expected = 0.0;
  for (int64_t b = 0; b * kSumBlock < n; ++b) {
    double block = 0.0;
    for (int64_t i = b * kSumBlock; i < std::min(n, (b + 1) * kSumBlock); ++i) block += x[i];
    expected += block;
  }
  for (int threads : {1, 2, 3}) {
    const double sum = with_threads(threads, [&] { return ordered_sum(n, [&](int64_t i) { return x[i]; }); });
    CHECK(same_bits(sum, expected));
  }
  // The data is such that a plain reduction's bits follow the thread count (what was fixed).
  auto reduction = [&] {
    return parallel_reduce(
        0, n, 0, 0.0, [&](double& sum, int64_t i) { sum += x[i]; }, [](double& sum, double part) { sum += part; });
  };
  CHECK_FALSE(same_bits(with_threads(1, reduction), with_threads(2, reduction)));
}

TEST_CASE("aspect_ratio_stats: serial == parallel to the bit on 240,000 triangles") {
  const auto a = big_torus();
  REQUIRE(a.num_triangles() >= kParallelMin);
  auto stats = [&] { return aspect_ratio_stats(a.positions.data(), a.triangles.data(), a.num_triangles()); };
  const AspectStats one = with_threads(1, stats), two = with_threads(2, stats), three = with_threads(3, stats);
  CHECK(same_bits(one.mean, two.mean));
  CHECK(same_bits(one.mean, three.mean));
  CHECK(same_bits(one.max, two.max));
  CHECK(one.degenerate == two.degenerate);
  // and the mean is the mean: against a plain serial sum, within rounding
  double sum = 0.0;
  for (int64_t t = 0; t < a.num_triangles(); ++t) {
    const int32_t* c = &a.triangles[3 * size_t(t)];
    sum += aspect_ratio(&a.positions[3 * size_t(c[0])], &a.positions[3 * size_t(c[1])], &a.positions[3 * size_t(c[2])]);
  }
  CHECK(one.mean == doctest::Approx(sum / double(a.num_triangles())).epsilon(1e-12));
}

TEST_CASE("Hausdorff sample count: serial == parallel to the bit on 240,000 triangles") {
  const auto a = big_torus();
  const Surface surface(a.positions, a.triangles);
  auto step = [&] { return step_for_sample_count(surface, 5000000); };
  CHECK(same_bits(with_threads(1, step), with_threads(2, step)));
  // An absurd step: the count in the message (beyond 2^53, where whole numbers round) is the same.
  auto message = [&] {
    try {
      sample_surface(surface, 1e-12);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string serial = with_threads(1, message);
  CHECK(serial.find("would need") != std::string::npos);
  CHECK(serial == with_threads(2, message));
}
