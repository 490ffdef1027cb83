// Processing time per 640x480 cloud: our obstacle pipeline and the textbook
// PCL pipeline (crop, 1 cm voxel grid, RANSAC plane, 2 cm Euclidean
// clustering) in the same run, on the same real scans
// (../shared/data/pointclouds/mosd_learn, 14 clouds, each processed `rounds`
// times in turn), pinned to one core. Google Benchmark drives the loop; the
// per-cloud percentiles are its counters (milliseconds):
//   cpu_p50_ms, cpu_p99_ms, cpu_max_ms  thread CPU time (the machine is
//                                       shared: time while descheduled is
//                                       not the code's cost)
//   wall_p50_ms, wall_p99_ms            wall-clock time
//
//   build/bench/cloud_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <functional>

#include "iplan/cloud/cloud.h"
#include "iplan/cloud/pipeline.h"
#include "iplan/core/process.h"
#include "iplan/core/stats.h"

namespace {

using iplan::cloud::Cloud;
using iplan::cloud::CloudParams;

constexpr int kRounds = 20;

const std::vector<Cloud>& Clouds() {
  static const std::vector<Cloud> clouds = [] {
    std::vector<std::string> files;
    for (const auto& e :
         std::filesystem::directory_iterator(std::string(IPLAN_SHARED_DIR) + "/data/pointclouds/mosd_learn"))
      if (e.path().extension() == ".pcd") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    std::vector<Cloud> out;
    for (const auto& f : files) out.push_back(iplan::cloud::LoadPcd(f));
    return out;
  }();
  return clouds;
}

using iplan::core::ThreadCpuSeconds;

// Runs `process` on every cloud in turn, one cloud per iteration, and
// reports the per-cloud percentiles.
void Run(benchmark::State& state, const std::function<std::size_t(const Cloud&)>& process) {
  const auto& clouds = Clouds();
  std::vector<double> cpu, wall;
  std::size_t k = 0, obstacles = 0;
  for (auto _ : state) {
    const Cloud& cloud = clouds[k++ % clouds.size()];
    const double c0 = ThreadCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    obstacles += process(cloud);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cpu.push_back(ThreadCpuSeconds() - c0);
    wall.push_back(seconds);
    state.SetIterationTime(seconds);
  }
  const auto c = iplan::core::Summarize(cpu);
  const auto w = iplan::core::Summarize(wall);
  state.counters["cpu_p50_ms"] = 1e3 * c.p50;
  state.counters["cpu_p99_ms"] = 1e3 * c.p99;
  state.counters["cpu_max_ms"] = 1e3 * c.max;
  state.counters["wall_p50_ms"] = 1e3 * w.p50;
  state.counters["wall_p99_ms"] = 1e3 * w.p99;
  state.counters["obstacles_per_cloud"] = static_cast<double>(obstacles) / std::max<std::size_t>(1, cpu.size());
}

void BM_Ours(benchmark::State& state) {
  iplan::cloud::ObstaclePipeline pipeline(CloudParams{});
  pipeline.Process(Clouds()[0]);  // warm-up: buffers sized
  Run(state, [&](const Cloud& c) { return pipeline.Process(c).obstacles.size(); });
}

void BM_Textbook(benchmark::State& state) {
  const CloudParams params;
  iplan::cloud::TextbookPipeline(Clouds()[0], params);  // warm-up
  Run(state, [&](const Cloud& c) { return iplan::cloud::TextbookPipeline(c, params).obstacles.size(); });
}

BENCHMARK(BM_Ours)->Iterations(14 * kRounds)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Textbook)->Iterations(14 * kRounds)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  // One core: the pipelines are single-threaded; pinning keeps the cache
  // and the figures comparable.
  iplan::core::PinToCurrentCpu();
  if (Clouds().size() != 14) {
    std::fprintf(stderr, "cloud_bench: expected the 14 mOSD learn scans, found %zu\n", Clouds().size());
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
