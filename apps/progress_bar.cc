#include "apps/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace handlabel {
namespace {

std::string Duration(double s) {
  char buf[32];
  if (s < 60) {
    std::snprintf(buf, sizeof(buf), "%.0fs", s);
  } else if (s < 3600) {
    std::snprintf(buf, sizeof(buf), "%dm%02ds", static_cast<int>(s / 60),
                  static_cast<int>(s) % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%dh%02dm", static_cast<int>(s / 3600),
                  static_cast<int>(s / 60) % 60);
  }
  return buf;
}

}  // namespace

ProgressBar::ProgressBar(int total, std::string unit, std::FILE* out, int is_tty,
                         double plain_interval_s)
    : total_(std::max(1, total)),
      unit_(std::move(unit)),
      out_(out),
      tty_(is_tty < 0 ? ::isatty(::fileno(out)) != 0 : is_tty != 0),
      plain_interval_s_(plain_interval_s),
      start_(std::chrono::steady_clock::now()) {}

std::string ProgressBar::Line(int done, double seconds) const {
  const double rate = seconds > 0 ? done / seconds : 0.0;
  char buf[160];
  std::string line;
  if (tty_) {
    const int width = 24;
    const int filled = static_cast<int>(static_cast<double>(width) * done / total_);
    line = "[" + std::string(filled, '#') + std::string(width - filled, '.') + "] ";
  }
  std::snprintf(buf, sizeof(buf), "%d/%d %s  %.1f %s/s", done, total_, unit_.c_str(),
                rate, unit_.c_str());
  line += buf;
  if (done < total_ && rate > 0) {
    line += "  ETA " + Duration((total_ - done) / rate);
  } else if (done >= total_) {
    line += "  in " + Duration(seconds);
  }
  return line;
}

void ProgressBar::Update(int done) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_done_ = std::max(last_done_, done);
  const double s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (tty_) {
    if (s - last_print_s_ < 0.1 && last_done_ < total_) return;  // ~10 redraws/s
    std::fprintf(out_, "\r%s\033[K", Line(last_done_, s).c_str());
  } else {
    if (s - last_print_s_ < plain_interval_s_) return;
    std::fprintf(out_, "%s\n", Line(last_done_, s).c_str());
  }
  std::fflush(out_);
  last_print_s_ = s;
}

void ProgressBar::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  const double s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(out_, tty_ ? "\r%s\033[K\n" : "%s\n", Line(last_done_, s).c_str());
  std::fflush(out_);
}

}  // namespace handlabel
