#pragma once
// How many of a loop's workers should run while other processes share the cores.
//
// With another process keeping one of two cores busy, the kernel's per-session
// fairness (autogroup) gives that process's session one core and ours the other: our
// two workers then share one core, each runnable half of the time, and only add cache
// traffic and lock hand-overs (`detect` 9 % slower than one worker, docs/speed.md
// "Threads under load"). The kernel says so directly: the time our threads spend
// runnable but waiting for a core (run-queue wait, /proc/self/task/*/schedstat).
//
// The governor watches that share over windows of the loop's own time. When the
// workers wait for a core more than `max_wait_share` of their runnable time, it parks
// workers until as many run as the cores they got between them (all but the first
// when two share one core); the running ones then wait for no core, so the governor
// cannot see the load leave: it lets every worker run again for one window after a
// pause (probe) and parks them again, with a doubled pause, if they still wait.
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>

namespace handlabel {

// The process's threads' scheduler times, summed over its threads (nanoseconds).
struct SchedulerTimes {
  double run_ns = 0;   // on a core
  double wait_ns = 0;  // runnable, waiting for a core
};

// Reads /proc/self/task/*/schedstat; nothing where the kernel does not provide it.
std::optional<SchedulerTimes> ProcessSchedulerTimes();

struct WorkerGovernorOptions {
  // Park the other workers when the run-queue wait exceeds this share of the runnable
  // time (run + wait). Two workers sharing one core wait ~0.5; on free cores ~0.0-0.1;
  // two workers with two other processes' threads in the same session ~0.33, where
  // they still get 1.33 cores between them and should keep running.
  double max_wait_share = 0.4;
  std::chrono::milliseconds window{500};
  std::chrono::milliseconds first_pause{4000};  // before the first probe
  std::chrono::milliseconds max_pause{32000};   // the doubling stops here
  // Before the loop: every worker's thread busy for this long, as a first window, so
  // that a loop on a busy machine parks before its workers start sharing one core
  // (their first items cost the most: buffers allocated, caches cold). 0 = none.
  std::chrono::milliseconds calibration{0};
};

class WorkerGovernor {
 public:
  using Clock = std::chrono::steady_clock;
  // `times` reads the scheduler times (tests pass their own); without them (nothing
  // returned) every worker always runs.
  WorkerGovernor(
      int workers, WorkerGovernorOptions options = {},
      std::function<std::optional<SchedulerTimes>()> times = ProcessSchedulerTimes,
      std::function<Clock::time_point()> now = Clock::now);

  // The calibration window (options.calibration): `workers` threads spin that long and
  // the window decides as any other. Call once, before the loop.
  void Calibrate();

  // Whether worker `index` (0-based) may take its next item now. Worker 0 always may.
  // Thread-safe; the first caller after a window ends evaluates it.
  bool MayRun(int index);

  int running() const;  // workers allowed now
  int parks() const;    // times the other workers were parked (for the log)

 private:
  void Evaluate(Clock::time_point now);

  const int workers_;
  const WorkerGovernorOptions options_;
  const std::function<std::optional<SchedulerTimes>()> times_;
  const std::function<Clock::time_point()> now_;
  mutable std::mutex mutex_;
  bool enabled_ = true;
  int running_;
  int parks_ = 0;
  Clock::time_point window_start_;
  SchedulerTimes window_times_;
  Clock::time_point probe_at_;
  std::chrono::milliseconds pause_;
};

}  // namespace handlabel
