// The replanning loop without a task: the robot holds where it was left,
// yields to a person coming at it, and starts a new task at once.
#include <algorithm>
#include <limits>
#include <memory>

#include <gtest/gtest.h>

#include "replanner_fixture.h"

namespace iplan::trajopt {
namespace {

TEST_F(ReplannerTest, IdleHoldsTheCurrentPose) {
  SetState(kSec, Ready(), Eigen::VectorXd::Zero(7));
  const CycleResult c = replanner_.Cycle(kSec);
  ASSERT_TRUE(c.publish);
  EXPECT_EQ(c.status, "idle");
  EXPECT_EQ(c.positions.col(0), Ready());
  EXPECT_EQ(c.positions.col(1), Ready());
  EXPECT_FALSE(replanner_.Cycle(10 * kSec).publish);  // the state went stale
}

// A person coming at the idle robot: with the monitor's rule predicted, the
// arm withdraws from where their hand is heading (instead of standing in
// their way until the monitor stops it, or they touch it), and returns to
// where it was left once they have gone back.
TEST_F(ReplannerTest, AnIdleRobotYieldsToAPersonComingAtItAndReturns) {
  const std::unique_ptr<planning::Planner> predicting = PredictingPlanner();
  Replanner replanner(*predicting, body_, ReplannerParams{});
  const collision::RobotModel& robot = predicting->robot();
  collision::RobotData d(robot);
  const int tool = static_cast<int>(robot.spheres.size()) - 1;
  const Eigen::Vector3d tool_W = ToolAtReady(robot);
  // The hand's x offset from the tool: 0.60 m, in at 0.35 m/s to 0.20 m
  // (inside S_p of a robot at rest), held there until 3 s, then back to 0.9 m.
  auto offset = [](double s) { return s < 3.0 ? std::max(0.20, 0.60 - 0.35 * s) : 0.90; };
  const int64_t t_start = 100 * kSec;
  int64_t t = t_start;
  Eigen::VectorXd q = Ready();
  std::vector<std::string> statuses;
  double closest = std::numeric_limits<double>::infinity();  // tool to hand, while the hand is in
  for (int k = 0; k < 60; ++k) {
    const std::vector<double> qv(q.data(), q.data() + q.size());
    ASSERT_EQ(replanner.UpdateRobotState(t, replanner.joint_names(), qv, std::vector<double>(7, 0.0)), std::nullopt);
    collision::JointMixture m = PersonAt(t, tool_W + Eigen::Vector3d(offset((t - t_start) * 1e-9), 0, 0));
    for (int step = 0; step < m.num_steps; ++step) {  // the hand where it will be at each step
      const Eigen::Vector3d hand = tool_W + Eigen::Vector3d(offset((t - t_start) * 1e-9 + 0.1 * step), 0, 0);
      const Eigen::Vector3d now = m.means[0][static_cast<std::size_t>(step) * m.joint_names.size() + 8];
      for (std::size_t j = 0; j < m.joint_names.size(); ++j)
        m.means[0][static_cast<std::size_t>(step) * m.joint_names.size() + j] += hand - now;
    }
    ASSERT_EQ(replanner.UpdatePrediction(m), std::nullopt);
    const CycleResult c = replanner.Cycle(t);
    ASSERT_TRUE(c.publish) << c.status;
    statuses.push_back(c.status);
    t += kSec / 10;
    q = At(c, t);
    collision::CalcForwardKinematics(robot, q, &d);
    if ((t - t_start) * 1e-9 < 3.0)
      closest = std::min(closest, (d.p_WS.col(tool) - (tool_W + Eigen::Vector3d(offset((t - t_start) * 1e-9), 0, 0))).norm());
  }
  EXPECT_NE(std::find_if(statuses.begin(), statuses.end(),
                         [](const std::string& s) { return s.find("yielding") != std::string::npos; }),
            statuses.end());
  // Standing still, the tool would have had the hand 0.20 m from its centre.
  EXPECT_GT(closest, 0.20 + 0.08);
  // Back where it was left.
  EXPECT_LT((q - Ready()).cwiseAbs().maxCoeff(), 0.02);
  EXPECT_EQ(statuses.back().rfind("idle", 0), 0u) << statuses.back();
}

// A robot standing by while a person is near (a fresh prediction, the
// standby plan holding it where it is) starts a new task at once: the
// task's first plan moves from its first step on instead of keeping the
// standby plan's frozen prefix, which held the robot 0.2 s at every task's
// start (iplan eval cell: about 1 s of idle per episode).
TEST_F(ReplannerTest, ARobotStandingByNearAPersonStartsItsTaskAtOnce) {
  const std::unique_ptr<planning::Planner> predicting = PredictingPlanner();
  Replanner replanner(*predicting, body_, ReplannerParams{});
  const Eigen::Vector3d hand = ToolAtReady(predicting->robot()) + Eigen::Vector3d(0.9, 0, 0);
  int64_t t = 100 * kSec;
  auto tick = [&] {
    const Eigen::VectorXd ready = Ready();
    const std::vector<double> q(ready.data(), ready.data() + ready.size());
    ASSERT_EQ(replanner.UpdateRobotState(t, replanner.joint_names(), q, std::vector<double>(7, 0.0)), std::nullopt);
    ASSERT_EQ(replanner.UpdatePrediction(PersonAt(t, hand)), std::nullopt);
  };
  for (int k = 0; k < 5; ++k) {
    tick();
    const CycleResult c = replanner.Cycle(t);
    ASSERT_TRUE(c.publish) << c.status;
    ASSERT_EQ(c.status, "idle");
    ASSERT_EQ(c.positions.cols() > 1, true);
    t += kSec / 10;
  }
  tick();
  ASSERT_EQ(replanner.StartTask({3, "reach", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
  const CycleResult c = replanner.Cycle(t);
  ASSERT_TRUE(c.publish) << c.status;
  EXPECT_EQ(c.start_ns, t);
  EXPECT_LT((c.positions.col(0) - Ready()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT((c.positions.col(1) - Ready()).cwiseAbs().maxCoeff(), 1e-3) << c.status;
}

}  // namespace
}  // namespace iplan::trajopt
