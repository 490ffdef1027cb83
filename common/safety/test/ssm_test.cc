// ISO/TS 15066 speed and separation monitoring (iplan/safety/ssm.h): the
// standard's terms, the speed scale that keeps the separation, the pair rule.
#include <gtest/gtest.h>

#include "iplan/safety/ssm.h"

namespace iplan::safety {
namespace {

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

}  // namespace
}  // namespace iplan::safety
