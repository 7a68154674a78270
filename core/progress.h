#pragma once
// Progress of a long run (labeling, synthesis, evaluation) on stderr: on a terminal a bar
// redrawn in place with frames/s and ETA; otherwise (cluster logs, pipes) one plain line
// per ~5 % of the frames, so logs stay short and greppable. Thread-safe.

#include <chrono>
#include <mutex>
#include <ostream>
#include <string>

namespace handlabel {

class Progress {
 public:
  // `total` frames to process; `interactive` draws the bar (use IsTerminal()).
  Progress(int total, std::ostream& out, bool interactive, std::string label = "label");
  // One frame finished (ok or failed).
  void FrameDone(bool failed);
  // For callers that report a running count instead: `done` frames are finished.
  void Update(int done);
  // Final line (a newline after the bar). Called by the destructor if not before.
  void Finish();
  ~Progress();

  // True when file descriptor `fd` is a terminal and TERM is not "dumb".
  static bool IsTerminal(int fd);
  // "1h02m", "3m07s", "12s".
  static std::string FormatDuration(double seconds);

 private:
  std::string Line(double elapsed) const;
  void Draw();  // with mutex_ held

  const int total_;
  std::ostream& out_;
  const bool interactive_;
  const std::string label_;
  const std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mutex_;
  int done_ = 0;
  int failed_ = 0;
  int next_plain_report_ = 0;
  bool finished_ = false;
};

}  // namespace handlabel
