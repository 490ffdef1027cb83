// Order statistics for the figures we quote (latency, cycle times).
#pragma once

#include <string>
#include <vector>

namespace iplan::core {

struct Summary {
  std::size_t count = 0;
  double min = 0, p50 = 0, p90 = 0, p99 = 0, max = 0, mean = 0;
};

/// Percentiles by nearest rank on a sorted copy. Empty input: all zeros.
Summary Summarize(std::vector<double> values);

/// The q-quantile (0..1) by nearest rank of already sorted values.
double QuantileSorted(const std::vector<double>& sorted, double q);

/// CPU time of the calling thread (s): what benchmarks quote beside wall
/// time, since on a shared machine time descheduled is not the code's cost.
double ThreadCpuSeconds();

}  // namespace iplan::core
