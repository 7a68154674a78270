#include "core/progress.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace handlabel {

Progress::Progress(int total, std::ostream& out, bool interactive, std::string label)
    : total_(total),
      out_(out),
      interactive_(interactive),
      label_(std::move(label)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { Finish(); }

bool Progress::IsTerminal(int fd) {
  const char* term = std::getenv("TERM");
  return ::isatty(fd) && !(term && std::strcmp(term, "dumb") == 0);
}

std::string Progress::FormatDuration(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  char text[32];
  if (s >= 3600) {
    std::snprintf(text, sizeof(text), "%ldh%02ldm", s / 3600, (s % 3600) / 60);
  } else if (s >= 60) {
    std::snprintf(text, sizeof(text), "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof(text), "%lds", s);
  }
  return text;
}

std::string Progress::Line(double elapsed) const {
  const double rate = elapsed > 0 ? done_ / elapsed : 0.0;
  std::ostringstream line;
  line << label_ << " ";
  if (interactive_) {
    const int width = 24;
    const int filled = total_ > 0 ? width * done_ / total_ : width;
    line << "[" << std::string(filled, '#') << std::string(width - filled, '.') << "] ";
  }
  line << done_ << "/" << total_ << " frames";
  char numbers[96];
  std::snprintf(numbers, sizeof(numbers), ", %.2f frames/s", rate);
  line << numbers;
  if (done_ < total_ && rate > 0)
    line << ", ETA " << FormatDuration((total_ - done_) / rate);
  if (done_ == total_) line << ", " << FormatDuration(elapsed);
  if (failed_ > 0) line << ", " << failed_ << " failed";
  return line.str();
}

void Progress::FrameDone(bool failed) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++done_;
  failed_ += failed;
  Draw();
}

void Progress::Update(int done) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (done <= done_) return;
  done_ = done;
  Draw();
}

void Progress::Draw() {
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (interactive_) {
    // Redraw at most 10 times a second, and always at the end.
    if (done_ == total_ || now - last_draw_ > std::chrono::milliseconds(100)) {
      out_ << "\r" << Line(elapsed) << "\033[K" << std::flush;
      last_draw_ = now;
    }
  } else if (done_ >= next_plain_report_ || done_ == total_) {
    out_ << Line(elapsed) << "\n" << std::flush;
    next_plain_report_ = done_ + std::max(1, total_ / 20);
  }
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (interactive_ && total_ > 0) out_ << "\n" << std::flush;
}

}  // namespace handlabel
