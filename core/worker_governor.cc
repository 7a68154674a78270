#include "core/worker_governor.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

namespace handlabel {

std::optional<SchedulerTimes> ProcessSchedulerTimes() {
  // Each thread's schedstat: "<ns on a core> <ns waiting on a run queue> <slices>".
  std::error_code error;
  std::filesystem::directory_iterator tasks("/proc/self/task", error);
  if (error) return std::nullopt;
  SchedulerTimes sum;
  bool any = false;
  for (const auto& task : tasks) {
    std::ifstream in(task.path() / "schedstat");
    double run = 0, wait = 0;
    if (!(in >> run >> wait)) continue;  // a thread that ended meanwhile
    sum.run_ns += run;
    sum.wait_ns += wait;
    any = true;
  }
  if (!any) return std::nullopt;
  return sum;
}

WorkerGovernor::WorkerGovernor(int workers, WorkerGovernorOptions options,
                               std::function<std::optional<SchedulerTimes>()> times,
                               std::function<Clock::time_point()> now)
    : workers_(std::max(1, workers)),
      options_(options),
      times_(std::move(times)),
      now_(std::move(now)),
      running_(workers_),
      pause_(options.first_pause) {
  window_start_ = now_();
  const std::optional<SchedulerTimes> start = times_();
  enabled_ = workers_ > 1 && start.has_value();
  if (start) window_times_ = *start;
}

void WorkerGovernor::Calibrate() {
  if (!enabled_ || options_.calibration.count() <= 0) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    window_start_ = now_();
    if (const std::optional<SchedulerTimes> times = times_()) window_times_ = *times;
  }
  const auto spin = [this] {
    const Clock::time_point end = Clock::now() + options_.calibration;
    while (Clock::now() < end) {
    }
  };
  std::vector<std::thread> spinners;
  for (int w = 1; w < workers_; ++w) spinners.emplace_back(spin);
  spin();
  for (std::thread& spinner : spinners) spinner.join();
  const std::lock_guard<std::mutex> lock(mutex_);
  Evaluate(now_());
}

bool WorkerGovernor::MayRun(int index) {
  if (index == 0) return true;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!enabled_) return true;
  const Clock::time_point now = now_();
  if (now - window_start_ >= options_.window) Evaluate(now);
  return index < running_;
}

void WorkerGovernor::Evaluate(Clock::time_point now) {
  const std::optional<SchedulerTimes> times = times_();
  if (!times) {  // schedstat went away: run everything, decide nothing more
    enabled_ = false;
    running_ = workers_;
    return;
  }
  const double run = times->run_ns - window_times_.run_ns;
  const double wait = times->wait_ns - window_times_.wait_ns;
  window_start_ = now;
  window_times_ = *times;
  if (running_ < workers_) {  // parked: the running workers wait for no core
    if (now >= probe_at_) running_ = workers_;
    return;
  }
  // Nothing ran, or a thread ended and took its times with it: no verdict.
  if (run < 0 || wait < 0 || run + wait <= 0) return;
  const double share = wait / (run + wait);
  if (share > options_.max_wait_share) {
    // As many workers as the cores they got between them (one when two share one core;
    // as many as there are cores when more workers than cores were asked for).
    running_ = std::clamp(static_cast<int>(std::lround(workers_ * (1 - share))), 1,
                          workers_ - 1);
    ++parks_;
    probe_at_ = now + pause_;
    pause_ = std::min(2 * pause_, options_.max_pause);
  } else {
    pause_ = options_.first_pause;  // the cores are free again (or were all along)
  }
}

int WorkerGovernor::running() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return running_;
}

int WorkerGovernor::parks() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return parks_;
}

}  // namespace handlabel
