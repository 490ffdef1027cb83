// Section trajopt read from its declaration (TrajoptSettings, then
// ReplannerParams): the documented defaults, the cell's own file, bad values
// named with the file.
#include "services/trajopt/trajopt_config.h"

#include <fstream>

#include <gtest/gtest.h>

#include "iplan/core/params.h"

namespace iplan::trajopt {
namespace {

const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";

TEST(TrajoptSettings, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(TrajoptSettings{})),
            "");
  EXPECT_EQ(TrajoptSettings{}.Validate(), "");
}

TEST(TrajoptSettings, TheCellsFileReadsCleanly) {
  core::ConfigSection file = core::ConfigSection::Load(kConfig + "/trajopt.yaml");
  core::ConfigSection section = file.Section("trajopt");
  const TrajoptConfig c = ReadTrajoptConfig(section);
  EXPECT_TRUE(file.Problems().empty()) << file.Problems().front();
  EXPECT_EQ(c.robot_file, kConfig + "/robots/panda.yaml");
  EXPECT_EQ(c.planner_file, kConfig + "/planner_replanning.yaml");
  EXPECT_EQ(c.safety_file, kConfig + "/safety.yaml");
  EXPECT_EQ(c.output.min_duration, 1.0);
  EXPECT_EQ(c.replanner.cycle_budget, 0.05);
  EXPECT_EQ(c.obstacle_timeout, 2.0);
}

TEST(TrajoptSettings, BadValuesAreNamedWithTheFile) {
  const std::string path = ::testing::TempDir() + "/trajopt_bad.yaml";
  for (const auto& [yaml, expected] : std::vector<std::pair<std::string, std::string>>{
           {"trajopt:\n  obstacle_timeout: 0.01\n", "obstacle_timeout must be in [0.1, 60] s"},
           {"trajopt:\n  output:\n    min_duration: 61\n", "output.min_duration must be in [0, 60] s"},
           {"trajopt:\n  use_prediction: maybe\n", "key 'trajopt.use_prediction'"},
           {"trajopt:\n  planning_step: 0\n", "planning_step"},
       }) {
    { std::ofstream(path) << yaml; }
    core::ConfigSection file = core::ConfigSection::Load(path);
    core::ConfigSection section = file.Section("trajopt");
    ReadTrajoptConfig(section);
    ASSERT_FALSE(file.Problems().empty()) << yaml;
    EXPECT_NE(file.Problems().front().find(path), std::string::npos) << file.Problems().front();
    EXPECT_NE(file.Problems().front().find(expected), std::string::npos) << file.Problems().front();
  }
}

}  // namespace
}  // namespace iplan::trajopt
