#include "services/trajopt/core/obstacle_set.h"

#include <cmath>

#include <gtest/gtest.h>

namespace iplan::trajopt {
namespace {

constexpr int64_t kSecond = 1'000'000'000;

ObstacleBox Box(uint32_t id, double x, double half = 0.05) {
  ObstacleBox b;
  b.id = id;
  b.centre = {x, 0.0, half};
  b.half_extents = Eigen::Vector3d::Constant(half);
  return b;
}

TEST(ObstacleSet, NewBoxesChangeTheSetJitterDoesNot) {
  ObstacleSet set(2.0);
  bool changed = false;
  EXPECT_EQ(set.Update(1 * kSecond, {Box(1, 0.5)}, &changed), std::nullopt);
  EXPECT_TRUE(changed);
  EXPECT_EQ(set.Update(2 * kSecond, {Box(1, 0.505)}, &changed), std::nullopt);  // 5 mm: noise
  EXPECT_FALSE(changed);
  EXPECT_EQ(set.Update(3 * kSecond, {Box(1, 0.53)}, &changed), std::nullopt);  // 30 mm: moved
  EXPECT_TRUE(changed);
  const auto objects = set.SceneObjects();
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_EQ(objects[0].name, "obstacle 1");
  EXPECT_DOUBLE_EQ(objects[0].X_WO.translation().x(), 0.53);
  EXPECT_EQ(objects[0].size, Eigen::Vector3d::Constant(0.1));
}

TEST(ObstacleSet, AVanishedBoxIsRemovedAfterTheTimeoutOnly) {
  ObstacleSet set(2.0);
  bool changed = false;
  ASSERT_EQ(set.Update(0, {Box(1, 0.5), Box(2, 0.8)}, &changed), std::nullopt);
  ASSERT_EQ(set.Update(1 * kSecond, {Box(2, 0.8)}, &changed), std::nullopt);  // box 1 not seen
  EXPECT_FALSE(changed);
  EXPECT_FALSE(set.Expire(2 * kSecond));  // 2.0 s since box 1 was seen: still kept
  EXPECT_EQ(set.size(), 2u);
  EXPECT_TRUE(set.Expire(2 * kSecond + 1));
  ASSERT_EQ(set.size(), 1u);
  EXPECT_EQ(set.SceneObjects()[0].name, "obstacle 2");
  EXPECT_TRUE(set.Expire(10 * kSecond));
  EXPECT_EQ(set.size(), 0u);
}

TEST(ObstacleSet, FlatBoxesAreThickenedAndBadArraysRefused) {
  ObstacleSet set(1.0, 0.005);
  ObstacleBox flat = Box(3, 0.4);
  flat.half_extents.z() = 0.0;
  ASSERT_EQ(set.Update(0, {flat}, nullptr), std::nullopt);
  EXPECT_DOUBLE_EQ(set.SceneObjects()[0].size.z(), 0.01);
  EXPECT_NE(set.Update(0, {Box(4, 0.1), Box(4, 0.2)}, nullptr), std::nullopt);
  ObstacleBox nan = Box(5, 0.1);
  nan.centre.y() = std::nan("");
  EXPECT_NE(set.Update(0, {nan}, nullptr), std::nullopt);
  EXPECT_EQ(set.size(), 1u);  // refused arrays change nothing
  EXPECT_THROW(ObstacleSet(0.0), std::invalid_argument);
}

// An oriented box keeps its turn in the scene; turning it past the
// tolerance changes the set, a small wobble does not; a box whose
// orientation is not a rotation is refused.
TEST(ObstacleSet, OrientedBoxesKeepTheirTurn) {
  ObstacleSet set(2.0);
  ObstacleBox b = Box(1, 0.5);
  b.half_extents = {0.15, 0.1, 0.1};
  b.orientation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  bool changed = false;
  ASSERT_EQ(set.Update(0, {b}, &changed), std::nullopt);
  const auto objects = set.SceneObjects();
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_TRUE(objects[0].X_WO.linear().isApprox(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
  EXPECT_TRUE(objects[0].size.isApprox(Eigen::Vector3d(0.3, 0.2, 0.2), 1e-12));
  b.orientation = Eigen::AngleAxisd(0.32, Eigen::Vector3d::UnitZ());  // a corner moves 0.02 x 0.21 m: noise
  ASSERT_EQ(set.Update(1, {b}, &changed), std::nullopt);
  EXPECT_FALSE(changed);
  b.orientation = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ());  // 0.2 x 0.21 m: turned
  ASSERT_EQ(set.Update(2, {b}, &changed), std::nullopt);
  EXPECT_TRUE(changed);
  b.orientation.coeffs() << 0, 0, 0, 0;
  EXPECT_NE(set.Update(3, {b}, nullptr), std::nullopt);
}

}  // namespace
}  // namespace iplan::trajopt
