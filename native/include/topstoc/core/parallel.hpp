// The engine's threads: a small pool of its own on std::thread (no OpenMP runtime to ship next to
// a host's), parallel loops with fixed static chunks, and when threads pay off at all.
//
// Each parallel call runs on a pool of workers of its own for its duration, taken from the idle
// pools (or made) and grown to the team it asks for; the caller works as member 0. A parallel call
// made inside a worker runs serially in it. Pools and their workers last as long as the process. Between calls, idle workers spin for a
// few tens of microseconds (the next of consecutive loops follows within microseconds) and then
// sleep: nothing spins during the serial steps between loops, nor when the engine is idle.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

#if defined(_MSC_VER)
#define TOPSTOC_NOINLINE __declspec(noinline)
#define TOPSTOC_RESTRICT
#elif defined(__GNUC__) || defined(__clang__)
#define TOPSTOC_NOINLINE __attribute__((noinline))
#define TOPSTOC_RESTRICT __restrict__
#else
#define TOPSTOC_NOINLINE
#define TOPSTOC_RESTRICT
#endif

namespace topstoc {

namespace detail {
// A loop's steps run in a function of their own, as OpenMP outlines a loop: the compiler then
// inlines the body into this small function (inside a large caller it stops inlining), and the
// closure is reached through this reference alone, so stores through byte pointers in the body
// do not force its captures to be read again at every step.
template <class F>
TOPSTOC_NOINLINE void run_range(int64_t begin, int64_t end, F& TOPSTOC_RESTRICT body) {
  for (int64_t i = begin; i < end; ++i) body(i);
}

// The same for a reduction, into a local copy of the partial that the body's stores cannot alias.
template <class T, class F>
TOPSTOC_NOINLINE void accumulate_range(int64_t begin, int64_t end, T& partial, F& TOPSTOC_RESTRICT accumulate) {
  T local = partial;
  for (int64_t i = begin; i < end; ++i) accumulate(local, i);
  partial = local;
}
}  // namespace detail

/// Loops shorter than this run on one thread: waking and joining workers costs more than they
/// save below it, and far more when other programs hold the cores (inside Blender a small
/// decimation became a hundred times slower with spinning threads).
constexpr int64_t kParallelMin = 100000;

/// The same for loops whose every step costs about as much as a hundred steps of a plain loop
/// (a sample's link in the partition check, an output vertex's fan): worth two threads much
/// sooner (at 10 % of a million-vertex mesh the partition check's per-sample loop ran on one).
constexpr int64_t kParallelMinCostly = kParallelMin / 50;

/// A minimum length for parallel_for and friends from a condition of the caller's own: any
/// length when true, none when false.
constexpr int64_t parallel_if(bool threads) { return threads ? 0 : INT64_MAX; }

/// Cores not busy right now: the usable cores (capped by TOPSTOC_NUM_THREADS, else
/// OMP_NUM_THREADS) minus the other runnable threads the kernel counts at this instant (Linux;
/// elsewhere the cap alone), at least 1.
int free_cores();

/// Sizes the calling thread's teams to its share of free_cores(): engine calls running at the
/// same time (say two preview updates on two threads) split the free cores between them instead
/// of each taking them all. Results never depend on the number of threads.
void use_free_cores();

/// Marks one engine call as running for its lifetime (counted by use_free_cores); each engine
/// entry point holds one, then calls use_free_cores.
class RunningCall {
 public:
  RunningCall();
  ~RunningCall();
  RunningCall(const RunningCall&) = delete;
  RunningCall& operator=(const RunningCall&) = delete;
};

/// Team size of the calling thread's next parallel call (1 inside a worker).
int max_threads();

/// Sets the calling thread's team size (at least 1); use_free_cores sets it from the free cores.
void set_max_threads(int threads);

/// One stage of a call on the cores free now rather than when the call began (use_free_cores; a
/// live preview's rest starts beside a draft and is often alone by its later stages); the call's
/// team size is restored after (per-thread scratch sized for it stays valid).
class FreeCoresNow {
 public:
  FreeCoresNow() { use_free_cores(); }
  ~FreeCoresNow() { set_max_threads(saved_); }
  FreeCoresNow(const FreeCoresNow&) = delete;
  FreeCoresNow& operator=(const FreeCoresNow&) = delete;

 private:
  const int saved_ = max_threads();
};

/// The calling thread's index in the team it works for (0 outside parallel work).
int thread_index();

/// A contiguous range of indices.
struct Range {
  int64_t begin, end;
};

/// Member me's share of [begin, end) cut into team contiguous ranges in member order, the first
/// (end - begin) % team of them one longer: it depends on the length and the team size only.
inline Range static_chunk(int64_t begin, int64_t end, int me, int team) {
  const int64_t n = std::max<int64_t>(end - begin, 0), q = n / team, r = n % team;
  const int64_t first = begin + q * me + std::min<int64_t>(me, r);
  return {first, first + q + (me < r ? 1 : 0)};
}

class TeamState;

/// One member's view of a running team (the argument of a parallel_region's body).
class Team {
 public:
  Team(TeamState& state, int index, int size) : state_(state), index_(index), size_(size) {}
  int index() const { return index_; }
  int size() const { return size_; }
  /// Waits until every member has reached this barrier.
  void barrier();
  /// Runs f on member 0, then waits at a barrier (as OpenMP's single: no barrier before it).
  template <class F>
  void single(F f) {
    if (index_ == 0) f();
    barrier();
  }
  /// Runs f while no other member of the team runs a critical section.
  template <class F>
  void critical(F f) {
    lock();
    try {
      f();
    } catch (...) {
      unlock();
      throw;
    }
    unlock();
  }
  /// body(i) for this member's static chunk of [begin, end) (no barrier after it).
  template <class F>
  void for_static(int64_t begin, int64_t end, F&& body) const {
    const Range r = static_chunk(begin, end, index_, size_);
    detail::run_range(r.begin, r.end, body);
  }
  /// body(i) for runs of `grain` indices taken in turn from the shared counter `next` (set to the
  /// first index before the region) up to end, by whichever member is free (no barrier after it).
  template <class F>
  void for_dynamic(std::atomic<int64_t>& next, int64_t end, int64_t grain, F&& body) const {
    for (int64_t first; (first = next.fetch_add(grain, std::memory_order_relaxed)) < end;)
      detail::run_range(first, std::min(end, first + grain), body);
  }

 private:
  void lock();
  void unlock();
  TeamState& state_;
  int index_, size_;
};

namespace detail {
/// Runs run(context, team) on a team of `threads` (this thread as member 0; serially when
/// threads <= 1 or inside a worker); rethrows the first exception a member threw.
void run_team(int threads, void (*run)(void*, Team&), void* context);

/// The worker threads started so far in this process (they never end).
int worker_threads();
}  // namespace detail

/// Runs region(team) on `threads` threads at once, this one as member 0, and waits for them.
template <class F>
void parallel_region(int threads, F&& region) {
  detail::run_team(threads, [](void* f, Team& team) { (*static_cast<std::remove_reference_t<F>*>(f))(team); },
                   static_cast<void*>(&region));
}

namespace detail {
/// Runs f() on this thread as member 0 of a team of one (inside a worker, its index reads 0).
template <class F>
void serially(F&& f) {
  if (thread_index() == 0)
    f();
  else
    parallel_region(1, [&](Team&) { f(); });
}
}  // namespace detail

/// The team size for a loop of n steps: max_threads() when n >= min_parallel, else 1.
inline int team_for(int64_t n, int64_t min_parallel) { return n >= min_parallel ? max_threads() : 1; }

/// body(i) for every i in [begin, end): on max_threads() threads in static chunks when the loop
/// has min_parallel steps or more, else serially.
template <class F>
void parallel_for(int64_t begin, int64_t end, int64_t min_parallel, F&& body) {
  const int team = team_for(end - begin, min_parallel);
  if (team <= 1) {
    detail::serially([&] { detail::run_range(begin, end, body); });
    return;
  }
  parallel_region(team, [&](Team& t) { t.for_static(begin, end, body); });
}

/// body(i) for every i in [begin, end), handed out in runs of `grain` to whichever thread is free:
/// for steps of uneven cost whose results do not depend on which thread took them.
template <class F>
void parallel_for_dynamic(int64_t begin, int64_t end, int64_t grain, int64_t min_parallel, F&& body) {
  const int team = team_for(end - begin, min_parallel);
  if (team <= 1) {
    detail::serially([&] { detail::run_range(begin, end, body); });
    return;
  }
  std::atomic<int64_t> next{begin};
  parallel_region(team, [&](Team& t) { t.for_dynamic(next, end, grain, body); });
}

/// Each member's accumulate(partial, i) over its static chunk into its own partial (a copy of
/// identity), then combine(total, partial) in member order. For exact operations only (integer
/// sums, min, max, or): a floating-point sum's bits would follow the team size (ordered_sum.hpp).
template <class T, class Accumulate, class Combine>
T parallel_reduce(int64_t begin, int64_t end, int64_t min_parallel, const T& identity, Accumulate&& accumulate,
                  Combine&& combine) {
  const int team = team_for(end - begin, min_parallel);
  T total = identity;
  if (team <= 1) {
    detail::serially([&] { detail::accumulate_range(begin, end, total, accumulate); });
    return total;
  }
  struct alignas(64) Slot {
    T value;
  };
  std::vector<Slot> partial(size_t(team), Slot{identity});
  parallel_region(team, [&](Team& t) {
    const Range r = static_chunk(begin, end, t.index(), t.size());
    detail::accumulate_range(r.begin, r.end, partial[size_t(t.index())].value, accumulate);
  });
  for (const Slot& p : partial) combine(total, p.value);
  return total;
}

/// parallel_reduce for counts: accumulate(count, i) adds to a count of an exact (integer) type.
template <class T, class Accumulate>
T parallel_sum(int64_t begin, int64_t end, int64_t min_parallel, Accumulate&& accumulate) {
  return parallel_reduce(begin, end, min_parallel, T{}, accumulate, [](T& total, const T& part) { total += part; });
}

/// Sum of term(i) over [begin, end) for exact (integer) terms.
template <class T, class Term>
T parallel_count(int64_t begin, int64_t end, int64_t min_parallel, Term&& term) {
  return parallel_sum<T>(begin, end, min_parallel, [&](T& sum, int64_t i) { sum += term(i); });
}

/// Runs a() and b() at once on two threads when `threads` (else one after the other).
template <class A, class B>
void parallel_invoke(bool threads, A&& a, B&& b) {
  parallel_region(threads ? std::min(2, max_threads()) : 1, [&](Team& t) {
    if (t.size() == 1) {
      a();
      b();
    } else if (t.index() == 0) {
      a();
    } else {
      b();
    }
  });
}

}  // namespace topstoc
