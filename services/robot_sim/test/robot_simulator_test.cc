#include "services/robot_sim/core/robot_simulator.h"

#include <gtest/gtest.h>

#include "services/robot_sim/core/robot_sim_settings.h"
#include "iplan/core/params.h"

namespace iplan::robot_sim {
namespace {

constexpr int64_t kSec = 1000000000;

class RobotSimulatorTest : public ::testing::Test {
 protected:
  RobotSimulatorTest()
      : sim_(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"), Ready(),
             SimulatorParams{}) {}
  static Eigen::VectorXd Ready() {
    Eigen::VectorXd q(7);
    q << 0, -0.785, 0, -2.356, 0, 1.571, 0.785;
    return q;
  }
  std::vector<std::vector<double>> Points(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return {std::vector<double>(a.data(), a.data() + 7), std::vector<double>(b.data(), b.data() + 7)};
  }
  RobotSimulator sim_;
};

TEST_F(RobotSimulatorTest, FollowsATrajectoryWithinLimits) {
  Eigen::VectorXd goal = Ready();
  goal[0] = 1.2;
  goal[3] = -1.8;
  ASSERT_EQ(sim_.SetTrajectory(0, sim_.joint_names(), {0.0, 1.5}, Points(Ready(), goal)), std::nullopt);
  const auto& m = sim_.robot();
  Eigen::VectorXd prev_qd = sim_.qd();
  const double dt = 0.01;
  for (int k = 1; k <= 300; ++k) {
    sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
    for (int i = 0; i < 7; ++i) {
      const auto& lim = m.joints[static_cast<std::size_t>(m.q_joints[static_cast<std::size_t>(i)])].limits;
      ASSERT_LE(std::abs(sim_.qd()[i]), lim.velocity + 1e-9) << "joint " << i << " at step " << k;
      ASSERT_LE(std::abs(sim_.qd()[i] - prev_qd[i]) / dt, lim.acceleration + 1e-6) << "joint " << i;
      ASSERT_GE(sim_.q()[i], lim.lower);
      ASSERT_LE(sim_.q()[i], lim.upper);
    }
    prev_qd = sim_.qd();
  }
  EXPECT_LT((sim_.q() - goal).norm(), 1e-3);
}

TEST_F(RobotSimulatorTest, ProtectiveStopComesToRestWithinTheStoppingTime) {
  Eigen::VectorXd goal = Ready();
  goal[0] = 2.0;
  ASSERT_EQ(sim_.SetTrajectory(0, sim_.joint_names(), {0.0, 1.0}, Points(Ready(), goal)), std::nullopt);
  const double dt = 0.01;
  int k = 1;
  for (; k <= 50; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
  ASSERT_GT(sim_.qd().norm(), 0.5);
  sim_.Stop();
  const int stop_step = k;
  for (; k <= stop_step + 31; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
  EXPECT_EQ(sim_.qd().norm(), 0.0);  // at rest within 0.3 s (+ one step)
  const Eigen::VectorXd held = sim_.q();
  for (; k <= stop_step + 100; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
  EXPECT_EQ(sim_.q(), held);
  EXPECT_GT(sim_.last_stopping_distance(), 0.0);
  sim_.Resume();
  for (; k <= stop_step + 400; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
  EXPECT_LT((sim_.q() - goal).norm(), 1e-3);
}

// braking_fraction: a stop brakes every joint together (the direction of the
// joint velocity kept: the arm stays on its path) within the time the
// slowest joint needs at that fraction of its acceleration limit, never
// longer than stopping_time. Joint 1 of the Panda (limit 15 rad/s^2) at
// 1.2 rad/s: 0.08 s at the full limit, 0.16 s at half of it; joint 2
// (7.5 rad/s^2) at 1.5 rad/s would need 0.4 s at half: capped at 0.3 s.
TEST_F(RobotSimulatorTest, ProtectiveStopBrakesAtTheJointsAccelerationLimits) {
  const auto model = collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
  struct Case {
    double fraction;
    int joint;
    double speed, expected;
  };
  for (const Case& c : {Case{1.0, 0, 1.2, 0.08}, Case{0.5, 0, 1.2, 0.16}, Case{0.5, 1, 1.5, 0.3}, Case{0.0, 0, 1.2, 0.3}}) {
    SimulatorParams p;
    p.braking_fraction = c.fraction;
    RobotSimulator sim(model, Ready(), p);
    // Drive the joint at a constant speed towards its upper limit (1.6 s of
    // ramp), stop after 1 s.
    Eigen::VectorXd goal = Ready();
    goal[c.joint] += c.speed * 1.6;
    ASSERT_LT(goal[c.joint], model.UpperLimits()[c.joint]);
    ASSERT_EQ(sim.SetTrajectory(0, sim.joint_names(), {0.0, 1.6}, Points(Ready(), goal)), std::nullopt);
    const double dt = 0.001;
    int k = 1;
    for (; k <= 1000; ++k) sim.Step(static_cast<int64_t>(k * dt * kSec), dt);
    ASSERT_NEAR(sim.qd()[c.joint], c.speed, 1e-3) << "fraction " << c.fraction;
    sim.Stop();
    EXPECT_NEAR(sim.last_stop_duration(), c.expected, 1e-3) << "fraction " << c.fraction;
    const double decel = std::abs(sim.qd()[c.joint]) / sim.last_stop_duration();
    const int stop_step = k;
    double prev = sim.qd()[c.joint];
    for (; sim.qd().norm() > 0 && k < stop_step + 1000; ++k) {
      sim.Step(static_cast<int64_t>(k * dt * kSec), dt);
      const double a = std::abs(sim.qd()[c.joint] - prev) / dt;
      ASSERT_LE(a, decel + 1e-6) << "fraction " << c.fraction;  // uniform (the last step: what was left)
      if (c.fraction > 0 && c.expected < 0.3) {  // within the fraction of the limit unless the stopping time binds
        ASSERT_LE(a, c.fraction * (c.joint == 0 ? 15.0 : 7.5) + 1e-6);
      }
      prev = sim.qd()[c.joint];
    }
    EXPECT_NEAR((k - stop_step) * dt, c.expected, 2 * dt) << "fraction " << c.fraction;
  }
  SimulatorParams bad;
  bad.braking_fraction = 1.5;
  EXPECT_EQ(bad.Validate(), "braking_fraction must be in [0, 1]");
}

// Speed reduction: at half scale the path's time runs half as fast, so the
// robot is where the trajectory is at half the elapsed time, moving at half
// its speed; back at full scale it keeps that lag; a new trajectory starts on
// time again.
TEST_F(RobotSimulatorTest, SpeedReductionTimeScalesThePath) {
  Eigen::VectorXd goal = Ready();
  goal[0] = 1.0;  // 0.5 rad/s for 2 s
  ASSERT_EQ(sim_.SetTrajectory(0, sim_.joint_names(), {0.0, 2.0}, Points(Ready(), goal)), std::nullopt);
  const double dt = 0.01;
  int k = 1;
  for (; k <= 20; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);  // 0.2 s at full speed
  sim_.SetSpeedScale(0.5);
  for (; k <= 120; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);  // 1 s at half speed
  EXPECT_NEAR(sim_.path_lag(), 0.5, 1e-9);
  EXPECT_NEAR(sim_.qd()[0], 0.25, 1e-6);
  EXPECT_NEAR(sim_.q()[0], 0.5 * (1.2 - 0.5), 0.01);  // where the trajectory is at 0.7 s
  sim_.SetSpeedScale(1.0);
  for (; k <= 150; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
  EXPECT_NEAR(sim_.path_lag(), 0.5, 1e-9);
  EXPECT_NEAR(sim_.qd()[0], 0.5, 1e-4);
  sim_.SetSpeedScale(0.0);  // a pause along the path
  for (; k <= 200; ++k) sim_.Step(static_cast<int64_t>(k * dt * kSec), dt);
  EXPECT_NEAR(sim_.qd()[0], 0.0, 1e-9);
  const Eigen::VectorXd held = sim_.q();
  ASSERT_EQ(sim_.SetTrajectory(static_cast<int64_t>(k * dt * kSec), sim_.joint_names(), {0.0, 1.0}, Points(held, goal)),
            std::nullopt);
  EXPECT_EQ(sim_.path_lag(), 0.0);
  EXPECT_EQ(sim_.speed_scale(), 0.0) << "the scale is the monitor's, not the trajectory's";
  sim_.SetSpeedScale(std::nan(""));
  EXPECT_EQ(sim_.speed_scale(), 0.0) << "a non-finite scale holds the robot";
}

TEST_F(RobotSimulatorTest, RefusesBadTrajectories) {
  Eigen::VectorXd far = Ready();
  far[0] = 5.0;
  EXPECT_EQ(*sim_.SetTrajectory(0, sim_.joint_names(), {0.0, 1.0}, Points(Ready(), far)),
            "trajectory: point 1 puts panda_joint1 outside its limits");
  EXPECT_EQ(*sim_.SetTrajectory(0, {"a", "b"}, {0.0}, {{0.0, 0.0}}), "trajectory: missing joint 'panda_joint1'");
  EXPECT_EQ(*sim_.SetTrajectory(0, sim_.joint_names(), {1.0, 1.0}, Points(Ready(), Ready())), "trajectory: times do not increase");
}

TEST_F(RobotSimulatorTest, CountsEachTouchOnce) {
  const collision::HumanBodyModel body(collision::HumanBodyParams::DefaultUpperBody());
  Eigen::Matrix3Xd far(3, 9), near(3, 9);
  for (int j = 0; j < 9; ++j) {
    far.col(j) = Eigen::Vector3d(2.0, 0.0, 0.5 + 0.1 * j);
    near.col(j) = Eigen::Vector3d(0.3, 0.0, 0.5 + 0.02 * j);  // through the robot's hand
  }
  EXPECT_GT(sim_.UpdateContacts(far, body), 1.0);
  EXPECT_EQ(sim_.contacts(), 0);
  EXPECT_LT(sim_.UpdateContacts(near, body), 0.0);
  sim_.UpdateContacts(near, body);
  EXPECT_EQ(sim_.contacts(), 1);
  sim_.UpdateContacts(far, body);
  sim_.UpdateContacts(near, body);
  EXPECT_EQ(sim_.contacts(), 2);
  ASSERT_TRUE(sim_.min_separation_seen());
  EXPECT_LT(*sim_.min_separation_seen(), 0.0);
}

TEST(RobotSimSettings, TheDocumentedDefaultsAreTheDeclaredOnesAndValid) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(RobotSimSettings{})),
            "");
  RobotSimSettings s;
  EXPECT_EQ(s.Validate(), "");
  s.permits.max_validity = 5e-4;  // PermitGateParams' (0, 10]: the service no longer says [1e-3, 10]
  EXPECT_EQ(s.Validate(), "");
  s.simulator.stopping_time = 0;
  EXPECT_EQ(s.Validate(), "stopping_time must be > 0");
}

}  // namespace
}  // namespace iplan::robot_sim
