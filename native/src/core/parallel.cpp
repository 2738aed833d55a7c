#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "core/machine_load.hpp"

#if defined(__unix__) || defined(__APPLE__)
#include <pthread.h>
#endif

#if defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(_M_IX86)
#include <immintrin.h>
#define TOPSTOC_PAUSE() _mm_pause()
#elif defined(_MSC_VER) && defined(_M_ARM64)
#include <intrin.h>
#define TOPSTOC_PAUSE() __yield()
#elif defined(__aarch64__) || defined(__arm__)
#define TOPSTOC_PAUSE() __asm__ __volatile__("yield")
#else
#define TOPSTOC_PAUSE() ((void)0)
#endif

namespace topstoc {

namespace {

// How long a waiting thread spins before it sleeps: long enough for the next of consecutive
// loops (microseconds apart), short beside the serial steps between a decimation's batches. A
// longer spin burned a core per waiting thread on every batch, and on a busy machine the spinner
// took the core from the member it waited for (two threads then took many times the CPU of one).
constexpr std::chrono::microseconds kSpinTime{50};

// The thread limit the environment sets: TOPSTOC_NUM_THREADS, else OMP_NUM_THREADS (its first
// entry), else none.
int environment_limit() {
  for (const char* name : {"TOPSTOC_NUM_THREADS", "OMP_NUM_THREADS"}) {
    const char* text = std::getenv(name);
    if (!text || !*text) continue;
    const long value = std::strtol(text, nullptr, 10);
    if (value >= 1) return int(std::min(value, 4096L));
  }
  return 0;
}

// The most threads one team uses: the usable cores, capped by the environment.
int ceiling() {
  static const int value = [] {
    const int cores = usable_cores(), limit = environment_limit();
    return std::max(1, limit > 0 ? std::min(cores, limit) : cores);
  }();
  return value;
}

thread_local int t_max_threads = 0;  // 0: not set, ceiling()
thread_local int t_index = 0;
thread_local bool t_in_team = false;  // inside a team of two or more (nested calls run serially)

// Spin-then-sleep waiting on a condition other threads make true: ready() must read only
// atomics, and whoever makes it true calls wake() afterwards.
class Waiter {
 public:
  template <class Ready>
  void wait(Ready ready) {
    const auto start = std::chrono::steady_clock::now();
    for (unsigned turn = 1;; ++turn) {
      if (ready()) return;
      TOPSTOC_PAUSE();
      if (turn % 64 == 0 && std::chrono::steady_clock::now() - start >= kSpinTime) break;
    }
    sleepers_.fetch_add(1);
    {
      std::unique_lock<std::mutex> lock(mutex_);
      condition_.wait(lock, ready);
    }
    sleepers_.fetch_sub(1);
  }
  // A sleeper counted itself before it checked ready() under the mutex: taking the mutex here
  // after the condition changed means it either sees the change or is waiting for this notify.
  void wake() {
    if (sleepers_.load() == 0) return;
    { std::lock_guard<std::mutex> lock(mutex_); }
    condition_.notify_all();
  }

 private:
  std::atomic<int> sleepers_{0};
  std::mutex mutex_;
  std::condition_variable condition_;
};

// Unwinds the members still running after another member threw.
struct Aborted {};

}  // namespace

class TeamState {
 public:
  explicit TeamState(int size) : size_(size) {}
  void barrier() {
    if (size_ <= 1) return;
    if (aborted_.load()) throw Aborted{};
    const uint64_t epoch = epoch_.load();
    if (arrived_.fetch_add(1) + 1 == size_) {
      arrived_.store(0);
      epoch_.fetch_add(1);
      waiter_.wake();
      return;
    }
    waiter_.wait([&] { return epoch_.load() != epoch || aborted_.load(); });
    if (epoch_.load() == epoch) throw Aborted{};
  }
  // Runs one member's share, keeping the first exception any member throws.
  void run_member(void (*run)(void*, Team&), void* context, int index) {
    try {
      Team team(*this, index, size_);
      run(context, team);
    } catch (const Aborted&) {
    } catch (...) {
      {
        std::lock_guard<std::mutex> lock(error_mutex_);
        if (!error_) error_ = std::current_exception();
      }
      aborted_.store(true);
      waiter_.wake();
    }
  }
  std::mutex& critical() { return critical_; }
  void rethrow() {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const int size_;
  std::atomic<int> arrived_{0};
  std::atomic<uint64_t> epoch_{0};
  std::atomic<bool> aborted_{false};
  Waiter waiter_;
  std::mutex critical_;
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

void Team::barrier() { state_.barrier(); }
void Team::lock() { state_.critical().lock(); }
void Team::unlock() { state_.critical().unlock(); }

namespace {

std::atomic<int> workers_started{0};  // in this process, for tests (detail::worker_threads)

// The workers one parallel call runs on. A job is one atomic word, (serial << 16) | team size,
// so a worker reads the number and the size of a job together. A pool is never destroyed and its
// workers never end (Pools says why).
class Pool {
 public:
  void run(int size, void (*run)(void*, Team&), void* context, TeamState& state) {
    while (workers_ < size - 1) {
      std::thread([this, id = workers_ + 1, seen = job_.load()] { work(id, seen); }).detach();
      ++workers_;
      workers_started.fetch_add(1);
    }
    run_ = run;
    context_ = context;
    state_ = &state;
    pending_.store(size - 1);
    job_.store(((job_.load() >> 16) + 1) << 16 | uint64_t(size));
    start_.wake();
    state.run_member(run, context, 0);
    done_.wait([&] { return pending_.load() == 0; });
  }

 private:
  void work(int id, uint64_t seen) {
    t_index = id;
    t_in_team = true;
    for (;;) {
      start_.wait([&] { return job_.load() != seen; });
      seen = job_.load();
      if (id >= int(seen & 0xFFFF)) continue;  // not in this team
      state_->run_member(run_, context_, id);
      if (pending_.fetch_sub(1) == 1) done_.wake();
    }
  }

  int workers_ = 0;  // changed by the call running on the pool only
  std::atomic<uint64_t> job_{0};
  void (*run_)(void*, Team&) = nullptr;  // the current job, written before job_ names it
  void* context_ = nullptr;
  TeamState* state_ = nullptr;
  std::atomic<int> pending_{0};  // workers of the current job still running
  Waiter start_, done_;
};

// The pools not running a call: a call takes one (the one last given back, whose workers are
// likely still spinning) and gives it back, so calls from several threads at once run on pools
// of their own, and a thread that ends leaves its pool to the next caller. Nothing here is ever
// destroyed, on purpose: an idle worker may be waiting on its pool even while the process exits.
// No destructor runs at thread exit either: mingw-w64 (emutls) ran thread_local destructors on
// storage it had already freed, and Windows runs them under the loader lock.
class Pools {
 public:
  Pool* take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (idle_.empty()) return new Pool;
    Pool* pool = idle_.back();
    idle_.pop_back();
    return pool;
  }
  void give(Pool* pool) {
    std::lock_guard<std::mutex> lock(mutex_);
    idle_.push_back(pool);
  }

 private:
  std::mutex mutex_;
  std::vector<Pool*> idle_;
};

std::atomic<Pools*> current_pools{nullptr};

// A forked child has only the thread that forked: it starts over with no pools (the inherited
// ones have no workers, and their lock may be held by a thread that is gone).
Pools& pools() {
  static const bool made = [] {
    current_pools.store(new Pools);
#if defined(__unix__) || defined(__APPLE__)
    pthread_atfork(nullptr, nullptr, [] { current_pools.store(new Pools); });
#endif
    return true;
  }();
  (void)made;
  return *current_pools.load();
}

}  // namespace

namespace detail {

void run_team(int threads, void (*run)(void*, Team&), void* context) {
  threads = std::min(threads, 0xFFFF);
  if (threads <= 1 || t_in_team) {  // serially, as member 0 of a team of one
    const int index = t_index;
    t_index = 0;
    TeamState state(1);
    struct Restore {
      int index;
      ~Restore() { t_index = index; }
    } restore{index};
    Team team(state, 0, 1);
    run(context, team);
    return;
  }
  struct Taken {  // the pool this call runs on, given back however the call ends
    Pools& pools;
    Pool* pool = pools.take();
    ~Taken() {
      t_in_team = false;
      pools.give(pool);
    }
  } taken{pools()};
  TeamState state(threads);
  t_in_team = true;
  taken.pool->run(threads, run, context, state);
  state.rethrow();
}

int worker_threads() { return workers_started.load(); }

}  // namespace detail

int max_threads() { return t_in_team ? 1 : (t_max_threads > 0 ? t_max_threads : ceiling()); }

void set_max_threads(int threads) { t_max_threads = std::max(1, threads); }

int thread_index() { return t_index; }

int free_cores() {
  const int others = other_runnable_threads();
  if (others < 0) return ceiling();
  return std::clamp(usable_cores() - others, 1, ceiling());
}

namespace {
std::atomic<int> running_calls{0};
}  // namespace

RunningCall::RunningCall() { running_calls.fetch_add(1); }
RunningCall::~RunningCall() { running_calls.fetch_sub(1); }

void use_free_cores() { set_max_threads(std::max(1, free_cores() / std::max(1, running_calls.load()))); }

}  // namespace topstoc
