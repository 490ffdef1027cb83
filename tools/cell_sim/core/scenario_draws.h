// Internal to the benchmarks of tools/cell_sim (interaction_benchmark.cc,
// shared_space.cc, cell_benchmark.cc, prediction_sources.h): the seeded
// draws every scenario is made of and the helpers both suites draw with.
// Units: m, rad, s; world frame W.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tools/cell_sim/core/interaction_benchmark.h"

namespace iplan::cell_sim::internal {

constexpr double kPi = 3.14159265358979323846;

// Scenario draws: a splitmix64 stream per scenario, so that scenario k is
// the same whatever the number of scenarios, and uniform numbers built from
// its bits (not std::uniform_*_distribution, whose output differs between
// standard libraries).
inline uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

class Draws {
 public:
  explicit Draws(uint64_t seed) : state_(seed) {}
  uint64_t Next() { return Mix(state_++); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  int Index(std::size_t n) { return static_cast<int>(Next() % n); }

 private:
  uint64_t state_;
};

struct NamedPose {
  std::string name;
  Eigen::VectorXd q;
};

std::vector<NamedPose> GraphPoses(const std::vector<GraphTask>& tasks);
/// The sequence shows every joint the benchmark needs.
bool Usable(const intent::SkeletonDataset& data, const intent::SkeletonSequence& s);
/// The planner's end effector at q (W).
Eigen::Isometry3d EndEffectorPose(const planning::Planner& planner, const Eigen::VectorXd& q);
/// A recorded person: subject `recorded` in turn, sequence, yaw, clip and delay.
void DrawRecordedPerson(const std::vector<std::string>& subjects,
                        const std::map<std::string, std::vector<const intent::SkeletonSequence*>>& by_subject,
                        int recorded, Draws* d, ScenarioSpec* s);
/// One of `tasks` from another of `poses`.
void DrawGraphTask(const std::vector<GraphTask>& tasks, const std::vector<NamedPose>& poses, Draws* d,
                   ScenarioSpec* s);
/// The true motion of the scenario's person for `duration` s.
PersonStream MakePersonStream(const BenchmarkSetup& setup, const ScenarioSpec& spec, double duration);
/// The shared-space suite's scenarios (shared_space.cc).
std::vector<ScenarioSpec> MakeSharedSpaceScenarios(const BenchmarkSetup& setup, int count, uint64_t seed);

}  // namespace iplan::cell_sim::internal
