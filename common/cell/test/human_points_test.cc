// cell::HumanPoints (iplan/cell/human_points.h): what a point's motion is,
// and what Check refuses, with its reason.
#include <gtest/gtest.h>

#include "iplan/cell/human_points.h"

namespace iplan::cell {
namespace {

HumanPoints TwoPoints() {
  HumanPoints p;
  p.means = Eigen::Matrix3Xd::Zero(3, 2);
  p.covariances.assign(2, 1e-4 * Eigen::Matrix3d::Identity());
  p.motion_of = {0, -1};
  p.motions.push_back({Eigen::Vector3d(0.3, 0, 0), 0.01 * Eigen::Matrix3d::Identity()});
  return p;
}

TEST(HumanPoints, APointsMotionIsItsPartsOrNone) {
  const HumanPoints p = TwoPoints();
  EXPECT_EQ(p.Check(), std::nullopt);
  ASSERT_NE(p.MotionOf(0), nullptr);
  EXPECT_DOUBLE_EQ(p.MotionOf(0)->velocity.x(), 0.3);
  EXPECT_EQ(p.MotionOf(1), nullptr);
  HumanPoints untracked = p;
  untracked.motion_of.clear();  // no point tracked
  EXPECT_EQ(untracked.Check(), std::nullopt);
  EXPECT_EQ(untracked.MotionOf(0), nullptr);
}

TEST(HumanPoints, CheckNamesWhatDoesNotFit) {
  HumanPoints p = TwoPoints();
  p.covariances.pop_back();
  EXPECT_EQ(p.Check(), "1 covariances for 2 points");
  p = TwoPoints();
  p.motion_of = {0};
  EXPECT_EQ(p.Check(), "motion_of has 1 entries for 2 points");
  p = TwoPoints();
  p.motion_of = {0, 1};
  EXPECT_EQ(p.Check(), "point 1 names motion 1 of 1");
  p = TwoPoints();
  p.motions[0].velocity.x() = std::nan("");
  EXPECT_EQ(p.Check(), "motion 0 is not finite");
  p = TwoPoints();
  p.motions[0].covariance(0, 1) = 0.001;
  EXPECT_EQ(p.Check(), "motion 0: velocity covariance not symmetric");
  p = TwoPoints();
  p.motions[0].covariance(0, 0) = -0.01;
  EXPECT_EQ(p.Check(), "motion 0: velocity covariance not positive semi-definite");
}

}  // namespace
}  // namespace iplan::cell
