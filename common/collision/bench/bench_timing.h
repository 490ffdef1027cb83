// Timing helpers of the collision benchmarks (collision_bench.cc,
// points_bench.cc): thread CPU time, medians and spread over repetitions.
#pragma once

#include <algorithm>
#include <chrono>
#include <ctime>
#include <functional>
#include <vector>

#include "iplan/core/stats.h"

namespace iplan::collision {

using Clock = std::chrono::steady_clock;

struct Stats {
  double median, min, max;
};

// CPU time of this thread (s); wall time is kept alongside.
using core::ThreadCpuSeconds;

inline double g_last_wall_median = 0.0;

// Runs `fn` (one batch of `work` items) `reps` times; each repetition repeats
// the batch until >= min_seconds of thread CPU time. Returns CPU seconds per
// item (median, min, max over repetitions); the wall-clock median goes to
// g_last_wall_median.
inline Stats Measure(const std::function<void()>& fn, double work, int reps, double min_seconds) {
  std::vector<double> per_item, wall;
  fn();  // warm-up
  for (int r = 0; r < reps; ++r) {
    long iters = 0;
    const double c0 = ThreadCpuSeconds();
    const auto t0 = Clock::now();
    double elapsed = 0.0;
    do {
      fn();
      ++iters;
      elapsed = ThreadCpuSeconds() - c0;
    } while (elapsed < min_seconds);
    per_item.push_back(elapsed / (iters * work));
    wall.push_back(std::chrono::duration<double>(Clock::now() - t0).count() / (iters * work));
  }
  std::sort(per_item.begin(), per_item.end());
  std::sort(wall.begin(), wall.end());
  g_last_wall_median = wall[wall.size() / 2];
  return {per_item[per_item.size() / 2], per_item.front(), per_item.back()};
}

}  // namespace iplan::collision
