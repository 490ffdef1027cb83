#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "iplan/core/params.h"

#include "iplan/planning/planner_params.h"

namespace iplan::planning {
namespace {

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(PlannerParams, DefaultsAreValid) {
  PlannerParams p;
  EXPECT_EQ(p.Validate(), "");
  EXPECT_EQ(p.num_optimizers, 8);
  EXPECT_DOUBLE_EQ(p.horizon, 3.0);
  EXPECT_DOUBLE_EQ(p.delta_cl, 0.95);
}

TEST(PlannerParams, ValidateNamesTheField) {
  PlannerParams p;
  p.delta_cl = 1.5;
  EXPECT_NE(p.Validate().find("delta_cl"), std::string::npos);
  p = PlannerParams{};
  p.dt = -0.1;
  EXPECT_NE(p.Validate().find("dt must be > 0, got -0.1"), std::string::npos);
  p = PlannerParams{};
  p.weights.obstacle = -1;
  EXPECT_NE(p.Validate().find("weights.obstacle"), std::string::npos);
  p = PlannerParams{};
  p.human_separation = -0.1;
  EXPECT_NE(p.Validate().find("human_separation must be >= 0, got -0.1"), std::string::npos);
}

TEST(PlannerParams, LoadsTheRepositoryConfig) {
  const PlannerParams p = LoadPlannerParams(std::string(IPLAN_SOURCE_DIR) + "/config/planner.yaml");
  EXPECT_EQ(p.Validate(), "");
  EXPECT_EQ(p.num_optimizers, 8);
}

TEST(PlannerParams, AKeyWrittenTwiceIsAnError) {
  // yaml-cpp would keep the first dt; the loop over the pairs would take the last.
  const std::string path = Write("twice.yaml", "dt: 0.05\nweights: {goal: 2.0}\ndt: 0.1\n");
  try {
    LoadPlannerParams(path);
    FAIL() << "a key written twice was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": key 'dt': appears twice (lines 1 and 3)");
  }
}

TEST(PlannerParams, LoadsValuesAndRejectsUnknownKeys) {
  const auto good = Write("good.yaml", "dt: 0.05\nnum_optimizers: 4\nweights: {goal: 2.0}\n"
                                       "allowed_collisions: [[panda_link0, table]]\n");
  const PlannerParams p = LoadPlannerParams(good);
  EXPECT_DOUBLE_EQ(p.dt, 0.05);
  EXPECT_EQ(p.num_optimizers, 4);
  EXPECT_DOUBLE_EQ(p.weights.goal, 2.0);
  ASSERT_EQ(p.allowed_collisions.size(), 1u);
  try {
    LoadPlannerParams(Write("bad.yaml", "dtt: 0.05\n"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key 'dtt'"), std::string::npos) << e.what();
  }
  try {
    LoadPlannerParams(Write("bad2.yaml", "num_optimizers: many\n"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("num_optimizers"), std::string::npos) << e.what();
  }
  EXPECT_EQ(LoadPlannerParams(Write("es.yaml", "early_stop_interval: 3\n")).early_stop_interval, 3);
  try {
    LoadPlannerParams(Write("bad4.yaml", "early_stop_interval: -1\n"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("early_stop_interval"), std::string::npos) << e.what();
  }
  try {
    LoadPlannerParams(Write("bad3.yaml", "horizon: 0.01\n"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("horizon"), std::string::npos) << e.what();
  }
}

TEST(PlannerParams, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(PlannerParams{})),
            "");
}

TEST(PlannerParams, OverridesReachTheFileAndAreCheckedLikeIt) {
  const auto path = Write("over.yaml", "dt: 0.05\n");
  const PlannerParams p = LoadPlannerParams(path, {{"max_iterations", "30"}, {"weights.goal", "2"}});
  EXPECT_EQ(p.max_iterations, 30);
  EXPECT_DOUBLE_EQ(p.weights.goal, 2.0);
  EXPECT_DOUBLE_EQ(p.dt, 0.05);
  try {
    LoadPlannerParams(path, {{"step_size", "1.5"}});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": step_size must be in (0, 1], got 1.5");
  }
}

}  // namespace
}  // namespace iplan::planning
