// Wall-clock seconds since a point in time, on the steady clock (never jumps with the
// system clock), for the timings jobs report.
#pragma once

#include <chrono>

namespace handlabel {

inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace handlabel
