// The cell's safety parameters come from one file (config/safety.yaml):
// the planner that predicts the monitor and the monitor read the same
// values, and a configuration in which they would disagree is refused,
// naming both files. Real configuration folders, copied and edited.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tools/cell_sim/cell_config.h"
#include "iplan/safety/safety_params.h"
#include "iplan/core/params.h"

namespace iplan::cell_sim {
namespace {

namespace fs = std::filesystem;

const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";

// A copy of the shipped configuration folder (models left out) to edit.
class CellConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("iplan_cell_config_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::copy(kConfig, dir_, fs::copy_options::recursive);
    fs::remove_all(dir_ / "models");
  }
  void TearDown() override { fs::remove_all(dir_); }

  void Edit(const std::string& file, const std::string& pattern, const std::string& replacement) {
    const fs::path p = dir_ / file;
    std::ifstream in(p);
    std::stringstream text;
    text << in.rdbuf();
    const std::string edited = std::regex_replace(text.str(), std::regex(pattern), replacement);
    ASSERT_NE(edited, text.str()) << "pattern '" << pattern << "' not in " << p;
    std::ofstream(p) << edited;
  }

  // The error LoadCellConfig gives, empty when it loads.
  std::string LoadError() {
    try {
      LoadCellConfig(dir_.string(), 1);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(CellConfigTest, PlannerAndMonitorReadTheSafetyFile) {
  Edit("safety.yaml", "delta_cl: 0\\.95", "delta_cl: 0.97");
  Edit("safety.yaml", "reaction_time: 0\\.1 ", "reaction_time: 0.12 ");
  const CellConfig c = LoadCellConfig(dir_.string(), 1);
  EXPECT_EQ(c.planner->params().delta_cl, 0.97);
  EXPECT_EQ(c.monitor->params().delta_cl, 0.97);
  EXPECT_EQ(c.planner->params().ssm.reaction_time, 0.12);
  EXPECT_EQ(c.monitor->params().ssm.reaction_time, 0.12);
  EXPECT_EQ(safety::SsmDifference(c.planner->params().ssm, c.monitor->params().ssm), "");
  EXPECT_TRUE(c.planner->params().predict_ssm);  // the shipped cell predicts its monitor
}

TEST_F(CellConfigTest, APlannerFileThatDisagreesIsRefusedNamingBothFiles) {
  Edit("planner_replanning.yaml", "predict_ssm: true", "predict_ssm: true\ndelta_cl: 0.9");
  const std::string why = LoadError();
  EXPECT_NE(why.find("planner_replanning.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("safety.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("delta_cl"), std::string::npos) << why;
}

TEST_F(CellConfigTest, AgreeingValuesGivenTwiceAreAccepted) {
  Edit("planner_replanning.yaml", "predict_ssm: true", "predict_ssm: true\ndelta_cl: 0.95");
  EXPECT_EQ(LoadError(), "");
}

TEST_F(CellConfigTest, AMonitorFileThatDisagreesIsRefusedNamingBothFiles) {
  Edit("collision_risk.yaml", "  slow_down_fraction:", "  iso_ts_15066:\n    stopping_time: 0.5\n  slow_down_fraction:");
  const std::string why = LoadError();
  EXPECT_NE(why.find("collision_risk.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("safety.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("iso_ts_15066.stopping_time 0.5 vs 0.3"), std::string::npos) << why;
}

TEST_F(CellConfigTest, AMonitorStopHorizonThatDisagreesIsRefusedAndTheSafetyFileReachesBoth) {
  Edit("collision_risk.yaml", "  slow_down_fraction:", "  stop_horizon: 0.5\n  slow_down_fraction:");
  const std::string why = LoadError();
  EXPECT_NE(why.find("collision_risk.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("safety.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("stop_horizon"), std::string::npos) << why;
}

TEST_F(CellConfigTest, ABadSafetyFileIsRefusedByName) {
  Edit("safety.yaml", "stopping_speed: 1\\.0", "stopping_speed: 0.0");
  const std::string why = LoadError();
  EXPECT_NE(why.find("safety.yaml"), std::string::npos) << why;
  EXPECT_NE(why.find("stopping_speed"), std::string::npos) << why;
}

TEST(SafetyParams, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(safety::SafetyParams{})),
            "");
}

TEST(SafetyParams, TheShippedFileHoldsTheDefaults) {
  const safety::SafetyParams shipped = safety::LoadSafetyParams(kConfig + "/safety.yaml");
  EXPECT_EQ(shipped.delta_cl, safety::SafetyParams{}.delta_cl);
  EXPECT_EQ(safety::SsmDifference(shipped.ssm, safety::SsmParams{}), "");
}

}  // namespace
}  // namespace iplan::cell_sim
