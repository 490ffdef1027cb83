#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plan_cli.h"

namespace iplan::planning {
namespace {

PlanCliOptions Base() {
  PlanCliOptions o;
  o.scene = std::string(IPLAN_SOURCE_DIR) + "/config/scenes/cell.yaml";
  o.robot = std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml";
  o.config = std::string(IPLAN_SOURCE_DIR) + "/config/planner.yaml";
  o.start = {0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8};
  o.goal = {0.6, 0.1, 0.0, -1.8, 0.0, 1.9, 0.8};
  o.threads = 2;
  o.seed = 3;
  o.json = true;
  return o;
}

TEST(PlanCli, JsonHasExactlyTheDocumentedKeysInOrder) {
  std::ostringstream out, err;
  ASSERT_EQ(RunPlanCommand(Base(), out, err), 0) << err.str() << out.str();
  const auto j = nlohmann::ordered_json::parse(out.str());
  std::vector<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"success", "planning_time_s", "max_collision_bound",
                                            "delay_s", "trajectory"}));
  EXPECT_TRUE(j["success"].get<bool>());
  EXPECT_DOUBLE_EQ(j["trajectory"]["dt"].get<double>(), 0.1);
  ASSERT_EQ(j["trajectory"]["positions"].size(), 31u);
  EXPECT_EQ(j["trajectory"]["positions"][0].size(), 7u);
  EXPECT_DOUBLE_EQ(j["trajectory"]["positions"][30][0].get<double>(), 0.6);
}

TEST(PlanCli, BadInputIsExitCode2WithTheReason) {
  PlanCliOptions o = Base();
  o.start = {0.0, 0.0};
  std::ostringstream out, err;
  EXPECT_EQ(RunPlanCommand(o, out, err), 2);
  EXPECT_NE(err.str().find("--start has 2 values, the robot has 7 joints"), std::string::npos) << err.str();
  o = Base();
  o.goal_pose = {0.5, 0, 0.3, 1, 0, 0, 0};
  std::ostringstream out2, err2;
  EXPECT_EQ(RunPlanCommand(o, out2, err2), 2);
  EXPECT_NE(err2.str().find("exactly one of --goal and --goal-pose"), std::string::npos);
}

TEST(PlanCli, GoalPoseAndPredictionFile) {
  PlanCliOptions o = Base();
  o.goal.clear();
  o.goal_pose = {0.5, 0.0, 0.3, 1.0, 0.0, 0.0, 0.0};
  o.prediction = std::string(IPLAN_SOURCE_DIR) + "/docs/examples/prediction_example.json";
  std::ostringstream out, err;
  const int code = RunPlanCommand(o, out, err);
  ASSERT_NE(code, 2) << err.str();
  const auto j = nlohmann::json::parse(out.str());
  EXPECT_EQ(j["success"].get<bool>(), code == 0);
  if (j["success"].get<bool>()) {
    EXPECT_LT(j["max_collision_bound"].get<double>(), 0.05);
  }
}

}  // namespace
}  // namespace iplan::planning
