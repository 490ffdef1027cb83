// Self-collision pairs found by sampling (self_collision.h), on the Panda's
// DH file and the UR5e's meshes.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "iplan/collision/robot_model.h"
#include "iplan/collision/self_collision.h"

namespace iplan::collision {
namespace {

SelfCollisionParams Samples(int n) {
  SelfCollisionParams p;
  p.samples = n;
  return p;
}

RobotModel Panda() { return LoadRobotModel(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"); }
RobotModel Ur5e() { return LoadRobotModel(std::string(IPLAN_SHARED_DIR) + "/robots/ur5e/ur5e.urdf"); }

std::set<std::pair<std::string, std::string>> Named(const RobotModel& m, const SelfCollisionModel& s, SkipReason r) {
  std::set<std::pair<std::string, std::string>> out;
  for (const LinkPair& p : s.skipped)
    if (p.reason == r) out.insert({m.link_names[p.link_a], m.link_names[p.link_b]});
  return out;
}

TEST(SelfCollision, AdjacentLinksAreTheTreeNeighboursWithGeometry) {
  const RobotModel ur = Ur5e();
  const SelfCollisionModel s = ComputeSelfCollision(ur, Samples(300));
  const std::set<std::pair<std::string, std::string>> adjacent = {
      {"base_link_inertia", "shoulder_link"}, {"shoulder_link", "upper_arm_link"}, {"upper_arm_link", "forearm_link"},
      {"forearm_link", "wrist_1_link"},       {"wrist_1_link", "wrist_2_link"},    {"wrist_2_link", "wrist_3_link"}};
  EXPECT_EQ(Named(ur, s, SkipReason::kAdjacent), adjacent);
  // 7 links with spheres: 21 pairs, each either skipped or checked.
  EXPECT_EQ(s.skipped.size() + s.checked.size(), 21u);
  EXPECT_FALSE(s.checked.empty());
  // The base never meets the wrist's last link... but the wrist can fold
  // into the upper arm: that pair stays checked.
  EXPECT_TRUE(std::find(s.checked.begin(), s.checked.end(),
                        std::pair{ur.FindLink("upper_arm_link"), ur.FindLink("wrist_2_link")}) != s.checked.end() ||
              std::find(s.checked.begin(), s.checked.end(),
                        std::pair{ur.FindLink("upper_arm_link"), ur.FindLink("wrist_3_link")}) != s.checked.end());
}

TEST(SelfCollision, SamplesFindFoldedArmsAndTheReadyPoseIsClear) {
  const RobotModel panda = Panda();
  const SelfCollisionModel s = ComputeSelfCollision(panda);
  EXPECT_FALSE(Named(panda, s, SkipReason::kAdjacent).empty());
  EXPECT_FALSE(Named(panda, s, SkipReason::kNever).empty());  // e.g. the base and the first links never meet
  RobotData d(panda);
  Eigen::VectorXd ready(7);
  ready << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
  CalcForwardKinematics(panda, ready, &d);
  EXPECT_GT(SelfDistance(panda, s, d), 0.0);
  // Configurations drawn afresh (another stream): some fold the arm into
  // itself, and the checked pairs see it.
  std::mt19937_64 rng(99);
  int folded = 0;
  for (int n = 0; n < 500; ++n) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i) q[i] = std::uniform_real_distribution<double>(panda.LowerLimits()[i], panda.UpperLimits()[i])(rng);
    CalcForwardKinematics(panda, q, &d);
    folded += SelfDistance(panda, s, d) < 0.0 ? 1 : 0;
  }
  EXPECT_GT(folded, 5);
  EXPECT_LT(folded, 450);
  // Deterministic for a seed.
  const SelfCollisionModel again = ComputeSelfCollision(panda);
  EXPECT_EQ(again.checked, s.checked);
  EXPECT_THROW(ComputeSelfCollision(panda, Samples(0)), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::collision
