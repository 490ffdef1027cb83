#include <gtest/gtest.h>

#include "iplan/cell/joint_trajectory.h"
#include "iplan/cell/ssm.h"
#include "iplan/cell/timed_prediction.h"

namespace iplan::cell {
namespace {

TEST(MapJointNames, FindsEachWantedNameAndNamesTheMissingOne) {
  std::vector<int> idx;
  EXPECT_FALSE(MapJointNames({"b", "x", "a"}, {"a", "b"}, &idx));
  EXPECT_EQ(idx, (std::vector<int>{2, 0}));
  const auto e = MapJointNames({"b"}, {"a", "b"}, &idx);
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, "missing joint 'a'");
}

TEST(JointTrajectory, InterpolatesLinearlyAndHoldsTheEnds) {
  JointTrajectory t;
  ASSERT_FALSE(JointTrajectory::FromPoints(1'000'000'000, {"j2", "j1"}, {0.0, 0.5, 1.5},
                                           {{0, 10}, {1, 11}, {3, 13}}, {"j1", "j2"}, &t));
  EXPECT_DOUBLE_EQ(t.PositionAt(0)[0], 10);                  // before the start: the first point
  EXPECT_DOUBLE_EQ(t.PositionAt(1'250'000'000)[0], 10.5);    // halfway through the first segment
  EXPECT_DOUBLE_EQ(t.PositionAt(1'250'000'000)[1], 0.5);
  EXPECT_DOUBLE_EQ(t.PositionAt(2'000'000'000)[1], 2.0);     // 0.5 s into a 1 s segment
  EXPECT_DOUBLE_EQ(t.PositionAt(9'000'000'000)[0], 13);      // after the end: the last point
}

TEST(JointTrajectory, RefusesBadPointsAndKeepsTheOldValue) {
  JointTrajectory t;
  t.times = {7};
  EXPECT_EQ(*JointTrajectory::FromPoints(0, {"a"}, {0, 0}, {{1}, {2}}, {"a"}, &t), "times do not increase");
  EXPECT_EQ(*JointTrajectory::FromPoints(0, {"a"}, {0}, {{1, 2}}, {"a"}, &t), "point 0 has the wrong size");
  EXPECT_EQ(*JointTrajectory::FromPoints(0, {"a"}, {0, 1}, {{1}}, {"a"}, &t), "times and points differ in size");
  EXPECT_EQ(*JointTrajectory::FromPoints(0, {"a"}, {0}, {{1}}, {"b"}, &t), "missing joint 'b'");
  EXPECT_EQ(*JointTrajectory::FromPoints(0, {"a"}, {0}, {{std::nan("")}}, {"a"}, &t),
            "point 0 has a non-finite position of a");
  EXPECT_EQ(t.times, std::vector<double>{7});
}

TEST(FiniteDifferences, UseTheStartVelocityAndStopAtTheEnd) {
  Eigen::MatrixXd Q(1, 3);
  Q << 0, 1, 3;
  Eigen::MatrixXd V, A;
  FiniteDifferenceVelocities(Q, 0.5, &V);
  ASSERT_EQ(V.cols(), 2);
  EXPECT_DOUBLE_EQ(V(0, 0), 2);
  EXPECT_DOUBLE_EQ(V(0, 1), 4);
  FiniteDifferenceAccelerations(Q, Eigen::VectorXd::Constant(1, 1.0), 0.5, &A);
  ASSERT_EQ(A.cols(), 3);
  EXPECT_DOUBLE_EQ(A(0, 0), (1 - 0 + (0 - 0.5)) / 0.25);  // q_{-1} = q_0 - qdot_0 dt
  EXPECT_DOUBLE_EQ(A(0, 1), (3 - 2 + 0) / 0.25);
  EXPECT_DOUBLE_EQ(A(0, 2), (3 - 6 + 1) / 0.25);          // q_{n+1} = q_n
}

TEST(Ssm, ProtectiveSeparationDistanceAddsTheStandardsTerms) {
  SsmParams p;  // T_r 0.1, T_s 0.3, S_s 0.15 at 1 m/s, C 0.1, Z_d 0.05, Z_r 0.02
  EXPECT_NEAR(ProtectiveSeparationDistance(p, 1.6, 0.5), 1.6 * 0.4 + 0.5 * 0.1 + 0.075 + 0.17, 1e-12);
  EXPECT_NEAR(ProtectiveSeparationDistance(p, 0, 0), 0.17, 1e-12);  // at rest: C + Z_d + Z_r only
  EXPECT_NEAR(StoppingDistance(p, 3.0), 0.15, 1e-12);              // capped at the measured S_s
  p.directed = false;
  EXPECT_NEAR(StoppingDistance(p, 0.0), 0.15, 1e-12);
}

// The speed-reduction side: the largest fraction of the robot's speed at
// which the separation keeps S_p, in both slopes of the directed S_p and
// undirected; 0 where even a robot at rest is inside, 1 where nothing need
// slow down.
TEST(Ssm, SpeedScaleIsTheFractionOfTheRobotSpeedThatKeepsTheProtectiveSeparation) {
  SsmParams p;
  const double v_h = 0.3, at_rest = ProtectiveSeparationDistance(p, v_h, 0.0);  // 0.29 m
  EXPECT_EQ(SpeedScaleFor(p, at_rest - 1e-6, v_h, 0.8), 0.0);
  EXPECT_EQ(SpeedScaleFor(p, ProtectiveSeparationDistance(p, v_h, 0.8) + 1e-9, v_h, 0.8), 1.0);
  EXPECT_EQ(SpeedScaleFor(p, at_rest, v_h, 0.0), 1.0);  // nothing moves closer
  // Below stopping_speed (slope T_r + S_s / 1 m/s = 0.25 s) and above it
  // (slope T_r once S_s is whole).
  for (const double v_r : {0.8, 2.5}) {
    for (const double d : {at_rest + 0.05, at_rest + 0.2, at_rest + 0.3}) {
      const double s = SpeedScaleFor(p, d, v_h, v_r);
      if (d >= ProtectiveSeparationDistance(p, v_h, v_r)) {
        EXPECT_EQ(s, 1.0);
        continue;
      }
      ASSERT_GT(s, 0.0);
      ASSERT_LT(s, 1.0);
      EXPECT_NEAR(ProtectiveSeparationDistance(p, v_h, s * v_r), d, 1e-12) << "v_r " << v_r << ", d " << d;
    }
  }
  EXPECT_NEAR(SpeedScaleFor(p, at_rest + 0.05, v_h, 0.8), 0.05 / 0.25 / 0.8, 1e-12);
  p.directed = false;  // S_s always in: only T_r v_r grows
  const double undirected_rest = ProtectiveSeparationDistance(p, v_h, 0.0);
  EXPECT_NEAR(SpeedScaleFor(p, undirected_rest + 0.04, v_h, 0.8), 0.04 / 0.1 / 0.8, 1e-12);
}

// The pair rule gives both scales: the stop's (d against S_p) and the slow
// down's (d - v_r speed_reduction_time: what the robot travels while it
// slows), and none for a retreat.
TEST(Ssm, PairRuleGivesTheSlowDownAndStopScales) {
  SsmParams p;
  const Eigen::Vector3d delta(0.35, 0, 0);                         // robot sphere 0.35 m from the human one (+x)
  const SsmPair in = SsmPairRule(p, delta, 0.1, Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.6, 0, 0));  // d 0.25 m
  EXPECT_NEAR(in.stop_scale, (0.25 - 0.17) / 0.25 / 0.6, 1e-12);
  EXPECT_NEAR(in.slow_scale, (0.25 - 0.6 * 0.1 - 0.17) / 0.25 / 0.6, 1e-12);
  // A sphere that does not come closer needs no slowing down: its scales are
  // the stop's (1 outside S_p of a robot at rest, 0 inside).
  const SsmPair still = SsmPairRule(p, delta, 0.1, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0.5, 0));
  EXPECT_EQ(still.slow_scale, 1.0);
  EXPECT_EQ(still.stop_scale, 1.0);
  EXPECT_TRUE(in.violates());
  const SsmPair away = SsmPairRule(p, Eigen::Vector3d(0.2, 0, 0), 0.1, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.3, 0, 0));
  EXPECT_TRUE(away.retreating);
  EXPECT_EQ(away.stop_scale, 1.0);
  EXPECT_EQ(away.slow_scale, 1.0);
}

TEST(TimedPrediction, StepKIsOneStepAfterTheObservationPlusK) {
  collision::HumanBodyModel body(collision::HumanBodyParams::DefaultUpperBody());
  collision::JointMixture m;
  m.t0_ns = 5'000'000'000;
  m.time_step = 0.1;
  m.num_steps = 2;
  m.joint_names = body.params().joints;
  m.actions = {"reach"};
  m.probabilities = {1.0};
  const std::size_t J = m.joint_names.size();
  m.means.assign(1, std::vector<Eigen::Vector3d>(2 * J, Eigen::Vector3d(1, 0, 1)));
  m.covariances.assign(1, std::vector<Eigen::Matrix3d>(2 * J, 0.01 * Eigen::Matrix3d::Identity()));
  TimedPrediction p;
  ASSERT_FALSE(TimedPrediction::Build(body, m, &p));
  EXPECT_EQ(p.num_steps(), 2);
  EXPECT_EQ(p.StepTime(0), 5'100'000'000);
  EXPECT_EQ(p.StepTime(1), 5'200'000'000);
  EXPECT_NEAR(p.StartRelativeTo(4'900'000'000), 0.2, 1e-12);
  EXPECT_TRUE(p.FreshAt(5'400'000'000, 500'000'000));
  EXPECT_FALSE(p.FreshAt(5'600'000'000, 500'000'000));
  m.time_step = 0;
  EXPECT_TRUE(TimedPrediction::Build(body, m, &p));
  EXPECT_EQ(p.StepTime(0), 5'100'000'000) << "a refused prediction leaves the old one";
}

}  // namespace
}  // namespace iplan::cell
