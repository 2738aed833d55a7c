#include "topstoc/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
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

// How long a waiting thread spins before it sleeps. Consecutive loops of one decimation follow
// each other within microseconds, and waking a sleeping thread costs far more than that; a
// spin much longer than the gaps only burns a core the host (Blender) may want.
std::chrono::nanoseconds spin_time() {
  static const std::chrono::nanoseconds time = [] {
    const char* text = std::getenv("TOPSTOC_SPIN_US");  // for measuring only
    return std::chrono::microseconds(text && *text ? std::max(0L, std::strtol(text, nullptr, 10)) : 1000);
  }();
  return time;
}

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
    const auto limit = spin_time();
    for (unsigned turn = 1;; ++turn) {
      if (ready()) return;
      TOPSTOC_PAUSE();
      if (turn % 64 == 0 && std::chrono::steady_clock::now() - start >= limit) break;
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

#ifdef _WIN32
std::atomic<bool> process_exiting{false};  // set by an atexit handler (watch_exit)
#endif

// The workers of one calling thread. A job is one atomic word, (serial << 16) | team size, so a
// worker reads the number and the size of a job together; size 0 tells the workers to exit.
// The workers share the job's state with the pool (shared_ptr), so a worker may outlive it.
class Pool {
 public:
  ~Pool() {
#ifdef _WIN32
    // At process exit Windows has already killed the workers, maybe inside a wait holding its
    // mutex: waking them would hang. Otherwise they are told to leave and detached, as joining
    // while this thread exits (thread_local) deadlocks on the loader lock.
    if (!process_exiting.load()) post(0);
    for (std::thread& thread : threads_) thread.detach();
#else
    post(0);
    for (std::thread& thread : threads_) thread.join();
#endif
  }

  void run(int size, void (*run)(void*, Team&), void* context, TeamState& state) {
    while (int(threads_.size()) < size - 1) {
      const int id = int(threads_.size()) + 1;
      threads_.emplace_back([shared = shared_, id, seen = shared_->job.load()] { work(*shared, id, seen); });
    }
    Shared& s = *shared_;
    s.run = run;
    s.context = context;
    s.state = &state;
    s.pending.store(size - 1);
    post(size);
    state.run_member(run, context, 0);
    s.done.wait([&] { return s.pending.load() == 0; });
  }

 private:
  struct Shared {
    std::atomic<uint64_t> job{0};
    void (*run)(void*, Team&) = nullptr;  // the current job, written before job names it
    void* context = nullptr;
    TeamState* state = nullptr;
    std::atomic<int> pending{0};  // workers of the current job still running
    Waiter start, done;
  };

  void post(int size) {
    Shared& s = *shared_;
    s.job.store(((s.job.load() >> 16) + 1) << 16 | uint64_t(size));
    s.start.wake();
  }

  static void work(Shared& s, int id, uint64_t seen) {
    t_index = id;
    t_in_team = true;
    for (;;) {
      s.start.wait([&] { return s.job.load() != seen; });
      seen = s.job.load();
      const int size = int(seen & 0xFFFF);
      if (size == 0) return;
      if (id >= size) continue;  // not in this team
      s.state->run_member(s.run, s.context, id);
      if (s.pending.fetch_sub(1) == 1) s.done.wake();
    }
  }

  std::vector<std::thread> threads_;
  std::shared_ptr<Shared> shared_ = std::make_shared<Shared>();
};

thread_local std::unique_ptr<Pool> t_pool;

// A forked child has only the thread that forked: the pool it inherited has no workers, so it is
// abandoned (not joined) and the next parallel call makes a new one.
std::atomic<unsigned> forks{0};
thread_local unsigned t_pool_fork = 0;

void watch_exit() {
#ifdef _WIN32
  static const bool registered = [] {
    std::atexit([] { process_exiting.store(true); });
    return true;
  }();
  (void)registered;
#endif
}

void watch_forks() {
#if defined(__unix__) || defined(__APPLE__)
  static const bool registered = [] {
    pthread_atfork(nullptr, nullptr, [] { forks.fetch_add(1); });
    return true;
  }();
  (void)registered;
#endif
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
  if (t_pool && t_pool_fork != forks.load()) (void)t_pool.release();  // its workers are gone
  if (!t_pool) {
    watch_forks();
    watch_exit();
    t_pool = std::make_unique<Pool>();
    t_pool_fork = forks.load();
  }
  TeamState state(threads);
  t_in_team = true;
  t_pool->run(threads, run, context, state);
  t_in_team = false;
  state.rethrow();
}

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
