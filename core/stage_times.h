// Wall seconds per named stage of a piece of work (a label job's frame: "read",
// "detect.palm", "fit.keypoints", ...; docs/labeling-jobs.md, "Where the time went"):
// each caller times the calls it makes on the steady clock and adds them up by name, so
// measuring costs two clock reads per call.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <utility>

#include "core/stopwatch.h"

namespace handlabel {

// Stage -> wall seconds. A dot names a part of a stage ("detect.palm" is part of the
// detector); the parts of a stage that a caller cannot tell apart go to "<stage>.other".
using StageSeconds = std::map<std::string, double>;

// Adds the wall time from construction to destruction to (*times)[stage], also when the
// timed code throws. `times` may be null: nothing is recorded. Not thread-safe: one
// timer per map at a time, or maps of their own per thread.
class StageTimer {
 public:
  StageTimer(StageSeconds* times, std::string stage)
      : times_(times),
        stage_(std::move(stage)),
        start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() {
    if (times_) (*times_)[stage_] += SecondsSince(start_);
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  StageSeconds* times_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

// `from` added stage by stage into `into`, each name prefixed with `prefix` ("" or e.g.
// "fit.").
inline void AddStageSeconds(const StageSeconds& from, StageSeconds* into,
                            const std::string& prefix = "") {
  for (const auto& [stage, seconds] : from) (*into)[prefix + stage] += seconds;
}

inline double TotalStageSeconds(const StageSeconds& times) {
  double total = 0;
  for (const auto& [stage, seconds] : times) total += seconds;
  return total;
}

}  // namespace handlabel
