// The engine's thread pool (core/parallel.hpp): static chunks that follow the length and team size
// only, loops and reductions equal to serial ones for any team, exceptions carried to the caller,
// nested calls serial, many calls in a row or from two threads at once, pools outliving their
// calling threads, and workers that sleep between calls.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <atomic>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#endif

#include "core/per_thread.hpp"
#include "topstoc/core/parallel.hpp"
#include "with_threads.hpp"

using namespace topstoc;

namespace {

constexpr int kTeams[] = {1, 2, 3, 7};

}  // namespace

TEST_CASE("static_chunk: contiguous ranges in member order, sizes within one, from n and the team only") {
  for (const int64_t n : {0, 1, 2, 5, 7, 100, 1000003})
    for (const int team : kTeams) {
      int64_t at = 10;
      for (int me = 0; me < team; ++me) {
        const Range r = static_chunk(10, 10 + n, me, team);
        CHECK(r.begin == at);
        const int64_t size = r.end - r.begin;
        CHECK((size == n / team || size == n / team + 1));
        CHECK(size == n / team + (me < n % team ? 1 : 0));
        at = r.end;
      }
      CHECK(at == 10 + n);
    }
  // Written out: 10 steps on 3 members.
  CHECK(static_chunk(0, 10, 0, 3).end == 4);
  CHECK(static_chunk(0, 10, 1, 3).begin == 4);
  CHECK(static_chunk(0, 10, 2, 3).begin == 7);
}

TEST_CASE("parallel_for: every index once, each on the member whose static chunk holds it") {
  for (const int64_t n : {0, 1, 2, 5, 250001})
    for (const int team : kTeams)
      with_threads(team, [&] {
        std::vector<int> visits(static_cast<size_t>(n), 0), member(static_cast<size_t>(n), -1);
        parallel_for(0, n, 0, [&](int64_t i) {
          ++visits[size_t(i)];
          member[size_t(i)] = thread_index();
        });
        CHECK(std::count(visits.begin(), visits.end(), 1) == n);
        for (int me = 0; me < team; ++me) {
          const Range r = static_chunk(0, n, me, team);
          for (int64_t i = r.begin; i < r.end; ++i) REQUIRE(member[size_t(i)] == me);
        }
      });
}

TEST_CASE("parallel_for below its minimum length runs on the calling thread") {
  with_threads(3, [] {
    const auto caller = std::this_thread::get_id();
    bool elsewhere = false;
    parallel_for(0, 1000, 1001, [&](int64_t) { elsewhere |= std::this_thread::get_id() != caller; });
    CHECK_FALSE(elsewhere);
    int calls = 0;
    parallel_for(5, 5, 0, [&](int64_t) { ++calls; });
    parallel_for(5, 3, 0, [&](int64_t) { ++calls; });
    CHECK(calls == 0);
    parallel_for(5, 6, 0, [&](int64_t i) { calls += int(i); });
    CHECK(calls == 5);
  });
}

TEST_CASE("per-thread lists appended in member order give the serial order for every team") {
  const int64_t n = 300007;
  std::vector<int32_t> serial;
  for (int64_t i = 0; i < n; ++i)
    if (i % 7 == 3) serial.push_back(int32_t(i));
  for (const int team : kTeams)
    with_threads(team, [&] {
      PerThread<std::vector<int32_t>> found(max_threads());
      parallel_for(0, n, 0, [&](int64_t i) {
        if (i % 7 == 3) found.mine().push_back(int32_t(i));
      });
      std::vector<int32_t> merged;
      append_and_clear(found, merged);
      CHECK(merged == serial);
    });
}

TEST_CASE("parallel_reduce and parallel_count equal the serial results for every team") {
  const int64_t n = 400009;
  std::vector<int64_t> x(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) x[size_t(i)] = (i * 7919) % 100003 - 50000;
  const int64_t sum = std::accumulate(x.begin(), x.end(), int64_t(0));
  const int64_t lo = *std::min_element(x.begin(), x.end()), hi = *std::max_element(x.begin(), x.end());
  for (const int team : kTeams)
    with_threads(team, [&] {
      CHECK(parallel_count<int64_t>(0, n, 0, [&](int64_t i) { return x[size_t(i)]; }) == sum);
      struct Bounds {
        int64_t lo, hi;
      };
      const Bounds b = parallel_reduce(
          0, n, 0, Bounds{INT64_MAX, INT64_MIN},
          [&](Bounds& acc, int64_t i) {
            acc.lo = std::min(acc.lo, x[size_t(i)]);
            acc.hi = std::max(acc.hi, x[size_t(i)]);
          },
          [](Bounds& total, const Bounds& part) {
            total.lo = std::min(total.lo, part.lo);
            total.hi = std::max(total.hi, part.hi);
          });
      CHECK(b.lo == lo);
      CHECK(b.hi == hi);
      CHECK(parallel_count<int>(0, 0, 0, [](int64_t) { return 1; }) == 0);
    });
}

TEST_CASE("parallel_for_dynamic: every index once, for grains that do and do not divide the length") {
  for (const int team : kTeams)
    for (const int64_t grain : {1, 3, 1024})
      with_threads(team, [&] {
        const int64_t n = 10007;
        std::vector<std::atomic<int>> visits(static_cast<size_t>(n));
        parallel_for_dynamic(0, n, grain, 0, [&](int64_t i) { visits[size_t(i)].fetch_add(1); });
        int64_t once = 0;
        for (auto& v : visits) once += v.load() == 1;
        CHECK(once == n);
      });
}

TEST_CASE("parallel_region: barrier and single order the members' steps") {
  for (const int team : kTeams)
    with_threads(team, [&] {
      const int size = max_threads();
      std::vector<int> written(size_t(size), 0), seen(size_t(size), 0);
      int total = 0;
      parallel_region(size, [&](Team& t) {
        CHECK(t.size() == size);
        CHECK(t.index() == thread_index());
        for (int round = 1; round <= 50; ++round) {
          written[size_t(t.index())] = round;
          t.barrier();
          int all = 0;
          for (int w : written) all += w == round;
          seen[size_t(t.index())] += all == size;
          t.barrier();
        }
        t.single([&] { total = std::accumulate(seen.begin(), seen.end(), 0); });
      });
      CHECK(total == 50 * size);
    });
}

TEST_CASE("an exception thrown in a body reaches the caller, and the pool works after it") {
  for (const int team : kTeams)
    with_threads(team, [&] {
      CHECK_THROWS_WITH_AS(parallel_for(0, 1000, 0,
                                        [](int64_t i) {
                                          if (i == 999) throw std::runtime_error("step 999");
                                        }),
                           "step 999", std::runtime_error);
      // A member throws while the others wait at a barrier: they are released, not left waiting.
      CHECK_THROWS_AS(parallel_region(max_threads(),
                                      [](Team& t) {
                                        if (t.index() == t.size() - 1) throw std::length_error("last member");
                                        t.barrier();
                                        t.barrier();
                                      }),
                      std::length_error);
      int64_t sum = 0;
      sum = parallel_count<int64_t>(0, 1000, 0, [](int64_t i) { return i; });
      CHECK(sum == 999 * 1000 / 2);
    });
}

TEST_CASE("a parallel call inside a worker runs serially there, as member 0 of a team of one") {
  with_threads(3, [] {
    const int64_t n = 30;
    std::vector<int> inner_ok(static_cast<size_t>(n), 0);
    parallel_for(0, n, 0, [&](int64_t i) {
      const auto me = std::this_thread::get_id();
      const int outer = thread_index();
      bool same_thread = true, index_zero = true;
      int64_t count = 0;
      CHECK(max_threads() == 1);
      parallel_for(0, 1000, 0, [&](int64_t) {
        same_thread &= std::this_thread::get_id() == me;
        index_zero &= thread_index() == 0;
        ++count;
      });
      inner_ok[size_t(i)] = same_thread && index_zero && count == 1000 && thread_index() == outer;
    });
    CHECK(std::count(inner_ok.begin(), inner_ok.end(), 1) == n);
    CHECK(max_threads() == 3);
  });
}

TEST_CASE("many short parallel calls in a row, and two calling threads at once") {
  with_threads(2, [] {
    int64_t total = 0;
    for (int call = 0; call < 3000; ++call) total += parallel_count<int64_t>(0, 3, 0, [](int64_t i) { return i; });
    CHECK(total == 3000 * 3);
  });
  std::vector<int64_t> sums(2, 0);
  auto caller = [&](int which) {
    set_max_threads(2);
    for (int call = 0; call < 500; ++call)
      sums[size_t(which)] += parallel_count<int64_t>(0, 101, 0, [](int64_t i) { return i; });
  };
  std::thread a(caller, 0), b(caller, 1);
  a.join();
  b.join();
  CHECK(sums[0] == 500 * 5050);
  CHECK(sums[1] == 500 * 5050);
}

namespace {

// Two threads each make one parallel call on three threads and end, as the preview's workers come
// and go. Member 0 of each waits until both calls run, so they hold two pools at once. Returns
// whether every member of both teams ran (each team adds its members' 1 + 2 + 3).
bool two_callers_at_once() {
  std::atomic<int> running{0};
  int64_t sums[2] = {0, 0};
  auto call = [&](int64_t* sum) {
    set_max_threads(3);
    parallel_region(3, [&](Team& t) {
      if (t.index() == 0) {
        running.fetch_add(1);
        while (running.load() < 2) std::this_thread::yield();
      }
      t.critical([&] { *sum += t.index() + 1; });
    });
  };
  std::thread a(call, &sums[0]), b(call, &sums[1]);
  a.join();
  b.join();
  return sums[0] == 6 && sums[1] == 6;
}

}  // namespace

TEST_CASE("calling threads that end leave their pools to later callers: no worker is started again") {
  CHECK(two_callers_at_once());  // two pools of two workers at least are idle now
  const int workers = detail::worker_threads();
  int rounds_ok = 0;
  for (int round = 0; round < 10; ++round) rounds_ok += two_callers_at_once();
  CHECK(rounds_ok == 10);
  CHECK(workers >= 4);
  CHECK(detail::worker_threads() == workers);
}

TEST_CASE("parallel_invoke runs both tasks, on two threads or one") {
  for (const bool threads : {false, true})
    with_threads(2, [&] {
      int a = 0, b = 0;
      parallel_invoke(threads, [&] { a = 1; }, [&] { b = 2; });
      CHECK(a + b == 3);
    });
}

TEST_CASE("free_cores lies between 1 and the usable cores") {
  const int cores = free_cores();
  CHECK(cores >= 1);
  CHECK(cores <= int(std::max(1u, std::thread::hardware_concurrency())));
}

#if defined(__unix__) || defined(__APPLE__)
TEST_CASE("a forked child makes a pool of its own instead of waiting for its parent's workers") {
  with_threads(2, [] {
    CHECK(parallel_count<int64_t>(0, 1000, 0, [](int64_t i) { return i; }) == 499500);  // the pool exists
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      const int64_t sum = parallel_count<int64_t>(0, 1000, 0, [](int64_t i) { return i; });
      _exit(sum == 499500 ? 0 : 1);
    }
    int status = 0;
    REQUIRE(waitpid(child, &status, 0) == child);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
  });
}
#endif

#if defined(__unix__) || defined(__APPLE__)
namespace {

// The process's CPU seconds so far (every thread's).
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

TEST_CASE("workers sleep between calls: serial gaps between parallel calls cost the process almost no CPU") {
  // Each call is followed by a 2 ms gap in which the caller sleeps, as the serial steps between a
  // decimation's batches. Workers that spun through the gaps (for a millisecond each, as before)
  // would add about 1 ms of CPU per gap; workers that sleep add a few tens of microseconds.
  // The least of three rounds: on a loaded machine one round can be charged a preempted wake-up.
  with_threads(2, [] {
    constexpr int kGaps = 40;
    int64_t total = parallel_count<int64_t>(0, 2, 0, [](int64_t i) { return i; });  // the worker exists
    double least = 1e9;
    for (int round = 0; round < 3; ++round) {
      const double before = process_cpu_seconds();
      for (int gap = 0; gap < kGaps; ++gap) {
        total += parallel_count<int64_t>(0, 2, 0, [](int64_t i) { return i; });
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      least = std::min(least, process_cpu_seconds() - before);
    }
    CHECK(total == 3 * kGaps + 1);
    CHECK(least < kGaps * 0.3e-3);
  });
}
#endif
