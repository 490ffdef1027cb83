// Conversions between builtin_interfaces Time/Duration and seconds.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>

#include "iplan/msg/types.h"

namespace iplan::msg {

/// Seconds since the Unix epoch.
inline double ToSeconds(const Time& t) { return t.sec + t.nanosec * 1e-9; }
inline double ToSeconds(const Duration& d) { return d.sec + d.nanosec * 1e-9; }

/// Nanoseconds since the epoch; comparable exactly.
inline int64_t ToNanoseconds(const Time& t) {
  return static_cast<int64_t>(t.sec) * 1000000000LL + t.nanosec;
}

inline Time TimeFromNanoseconds(int64_t ns) {
  Time t;
  int64_t sec = ns / 1000000000LL;
  int64_t rem = ns % 1000000000LL;
  if (rem < 0) {
    rem += 1000000000LL;
    --sec;
  }
  t.sec = static_cast<int32_t>(sec);
  t.nanosec = static_cast<uint32_t>(rem);
  return t;
}

inline Time TimeFromSeconds(double s) {
  return TimeFromNanoseconds(static_cast<int64_t>(std::llround(s * 1e9)));
}

inline Duration DurationFromSeconds(double s) {
  const Time t = TimeFromSeconds(s);
  Duration d;
  d.sec = t.sec;
  d.nanosec = t.nanosec;
  return d;
}

/// Wall-clock time now (system_clock, shared by processes and hosts with NTP/PTP).
inline Time Now() {
  return TimeFromNanoseconds(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::system_clock::now().time_since_epoch())
                                 .count());
}

}  // namespace iplan::msg
