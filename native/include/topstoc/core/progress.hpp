// Progress reporting and cancellation for long computations.
//
// A ProgressCallback receives the overall fraction done (0..1) and the current stage's name;
// returning false asks the computation to stop, which then throws Cancelled. Progress maps each
// stage onto its share of the whole run and calls the callback at most every 50 ms (and at every
// stage change), so inner loops may report as often as they like.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>

namespace topstoc {

using ProgressCallback = std::function<bool(double fraction, const char* stage)>;

/// Thrown when a ProgressCallback returns false.
class Cancelled : public std::runtime_error {
 public:
  explicit Cancelled(const std::string& stage) : std::runtime_error("cancelled during " + stage) {}
};

class Progress {
 public:
  explicit Progress(ProgressCallback callback) : callback_(std::move(callback)) {}

  /// Starts a stage covering [begin, end] of the whole run; always reports.
  void stage(const char* name, double begin, double end) {
    name_ = name;
    begin_ = begin;
    end_ = end;
    report(0.0, true);
  }

  /// Reports `fraction` (0..1) of the current stage; throttled. Throws Cancelled.
  void update(double fraction) { report(fraction, false); }

  /// The current stage's name.
  const char* name() const { return name_; }

 private:
  void report(double fraction, bool force) {
    if (!callback_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(50)) return;
    last_ = now;
    double overall = begin_ + (end_ - begin_) * (fraction < 0 ? 0 : fraction > 1 ? 1 : fraction);
    overall = reported_ = std::max(reported_, overall);  // a retried stage never moves the bar back
    if (!callback_(overall, name_)) throw Cancelled(name_);
  }

  ProgressCallback callback_;
  const char* name_ = "";
  double begin_ = 0.0, end_ = 1.0, reported_ = 0.0;
  std::chrono::steady_clock::time_point last_{};
};

/// A flag another thread sets to stop an engine call at its next cancel check (a live preview
/// drops a computation whose ratio the user moved away from).
using CancelFlag = std::atomic<bool>;

namespace detail {
inline thread_local const CancelFlag* current_cancel = nullptr;
}

/// Makes `flag` the calling thread's cancel flag for the scope's lifetime (null: none).
class CancelScope {
 public:
  explicit CancelScope(const CancelFlag* flag) : previous_(detail::current_cancel) { detail::current_cancel = flag; }
  ~CancelScope() { detail::current_cancel = previous_; }
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  const CancelFlag* previous_;
};

/// Throws Cancelled(stage) when the calling thread's cancel flag is set (checks between steps of
/// serial code; threads of a team have none).
inline void check_cancelled(const char* stage) {
  const CancelFlag* flag = detail::current_cancel;
  if (flag != nullptr && flag->load(std::memory_order_relaxed)) throw Cancelled(stage);
}

}  // namespace topstoc
