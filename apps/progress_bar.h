#pragma once
// A progress display for long commands. On a terminal: one line redrawn in place,
//   [#########.........] 120/400 frames  23.5 frames/s  ETA 12s
// otherwise (logs, CI): a plain line at most every `plain_interval_s` seconds and at
// the end, so logs stay short. Update() may be called from any thread.

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace handlabel {

class ProgressBar {
 public:
  // `unit` names what is counted ("frames"). Draws to `out` (stderr by default);
  // `is_tty` < 0 = detect from `out`.
  ProgressBar(int total, std::string unit, std::FILE* out = stderr, int is_tty = -1,
              double plain_interval_s = 5.0);
  void Update(int done);
  // Final line (always printed).
  void Finish();

 private:
  std::string Line(int done, double seconds) const;

  int total_;
  std::string unit_;
  std::FILE* out_;
  bool tty_;
  double plain_interval_s_;
  std::chrono::steady_clock::time_point start_;
  double last_print_s_ = -1e9;
  int last_done_ = 0;
  std::mutex mutex_;
};

}  // namespace handlabel
