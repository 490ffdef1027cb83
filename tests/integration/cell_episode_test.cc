// The whole cell, as users start it: `iplan demo` runs every service as a
// separate process on loopback DDS (the synthetic person, intent, collision
// risk, trajectory optimisation, the robot simulator and the supervisor) for
// one collaborative episode, on Cyclone DDS, on Fast DDS, and mixed (half the
// services on each vendor). Every robot task completes, the robot never
// touches the person's true body, and trajectories come with an end-to-end
// latency. The intent model is trained from the synthetic person on the first
// run (cached in config/models).
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;

struct Variant {
  std::string name;
  std::vector<std::string> args;
};

class CellEpisode : public ::testing::TestWithParam<Variant> {};

TEST_P(CellEpisode, TasksCompleteWithoutContact) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("iplan-cell-episode-" + GetParam().name + "-" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string summary = (dir / "summary.json").string();
  std::vector<std::string> argv = {BinPath("iplan"),  "demo",        "--episodes", "1",
                                   "--timeout",       "100",         "--summary",  summary,
                                   "--state-dir",     dir.string(),  "--domain",   std::to_string(UniqueDomain(31)),
                                   "--config-dir",    std::string(IPLAN_SOURCE_DIR) + "/config"};
  argv.insert(argv.end(), GetParam().args.begin(), GetParam().args.end());
  Process demo(argv);
  const auto rc = demo.Wait(200s);
  ASSERT_TRUE(rc.has_value()) << "demo did not finish\n" << demo.Stdout();
  EXPECT_EQ(*rc, 0) << demo.Stdout() << demo.Stderr();
  std::ifstream in(summary);
  ASSERT_TRUE(in.good()) << "no summary\n" << demo.Stdout() << demo.Stderr();
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["failure"], "");
  EXPECT_EQ(j["episodes_completed"], 1);
  EXPECT_EQ(j["tasks_completed"], 5);  // every task of config/tasks/table_top.yaml
  EXPECT_EQ(j["true_contacts"], 0.0);
  EXPECT_GT(j["min_separation_m"].get<double>(), 0.0);
  EXPECT_LT(j["max_collision_bound"].get<double>(), 0.05);  // 1 - delta_cl of the risk service
  EXPECT_GT(j["latency_ms"]["count"].get<int>(), 20);
  EXPECT_GT(j["latency_ms"]["p50"].get<double>(), 0.0);
  EXPECT_LT(j["latency_ms"]["p99"].get<double>(), 1000.0);  // sanity only: the target lives in the demo figures
  for (const auto& [service, code] : j["service_exit_codes"].items()) EXPECT_EQ(code, 0) << service;
  if (GetParam().name == "mixed") {
    EXPECT_NE(j["vendors"]["intent"], j["vendors"]["perception"]);
    EXPECT_NE(j["vendors"]["trajopt"], j["vendors"]["supervisor"]);
  }
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Vendors, CellEpisode,
                         ::testing::Values(Variant{"cyclonedds", {"--dds", "cyclonedds"}},
                                           Variant{"fastdds", {"--dds", "fastdds"}},
                                           Variant{"mixed", {"--dds", "cyclonedds", "--mixed"}}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace iplan::testing
