// Trajectories as they go out (ToTrajectory with TrajectoryOutput) and how a
// receiver reads their start (TrajectoryStartNs): planned stamps, ROS 2's
// "zero stamp = start on receipt", the minimum duration of a hold, and
// velocities from the positions.
#include <gtest/gtest.h>

#include "iplan/adapters/adapters.h"
#include "iplan/msg/check.h"
#include "iplan/msg/time.h"

namespace iplan::services {
namespace {

double Seconds(const msg::Duration& d) { return d.sec + 1e-9 * d.nanosec; }

TEST(ToTrajectory, AHoldLastsTheMinimumDurationAtTheSameStep) {
  Eigen::MatrixXd q(2, 2);
  q << 0.5, 0.5, -1.0, -1.0;  // hold: 2 points over 0.1 s
  TrajectoryOutput out;
  out.min_duration = 1.0;
  const int64_t start = 1'700'000'000'123'000'000;
  const msg::JointTrajectory t = ToTrajectory(start, {"a", "b"}, q, 0.1, out, start + 5'000'000);
  EXPECT_EQ(msg::ToNanoseconds(t.header.stamp), start);
  ASSERT_EQ(t.points.size(), 11u);
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    EXPECT_NEAR(Seconds(t.points[i].time_from_start), 0.1 * static_cast<double>(i), 1e-9);
    EXPECT_EQ(t.points[i].positions, (std::vector<double>{0.5, -1.0}));
    EXPECT_EQ(t.points[i].velocities, (std::vector<double>{0.0, 0.0}));
  }
}

TEST(ToTrajectory, ZeroStampRetimesFromPublicationAndDropsWhatIsPast) {
  Eigen::MatrixXd q(1, 5);
  q << 0.0, 0.1, 0.3, 0.6, 1.0;  // segment speeds 1, 2, 3, 4 rad/s at dt 0.1
  TrajectoryOutput out;
  out.zero_stamp = true;
  const int64_t start = 1'700'000'000'000'000'000;
  const int64_t published = start + 30'000'000;  // 30 ms after waypoint 0
  const msg::JointTrajectory t = ToTrajectory(start, {"a"}, q, 0.1, out, published);
  EXPECT_EQ(t.header.stamp.sec, 0);
  EXPECT_EQ(t.header.stamp.nanosec, 0u);
  ASSERT_EQ(t.points.size(), 4u);  // waypoint 0 is already past
  const std::vector<double> times = {0.07, 0.17, 0.27, 0.37};
  const std::vector<double> speeds = {1.5, 2.5, 3.5, 4.0};  // central inside, one-sided at the end
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(Seconds(t.points[i].time_from_start), times[i], 1e-9) << i;
    EXPECT_DOUBLE_EQ(t.points[i].positions.at(0), q(0, static_cast<Eigen::Index>(i + 1)));
    EXPECT_NEAR(t.points[i].velocities.at(0), speeds[i], 1e-9) << i;
  }
}

TEST(ToTrajectory, WithoutVelocitiesTheyAreEmptyAndTheEndIsHeldStill) {
  Eigen::MatrixXd q(1, 3);
  q << 0.0, 0.2, 0.4;
  TrajectoryOutput out;
  out.velocities = false;
  const msg::JointTrajectory plain = ToTrajectory(0, {"a"}, q, 0.1, out, 0);
  ASSERT_EQ(plain.points.size(), 3u);
  for (const auto& p : plain.points) EXPECT_TRUE(p.velocities.empty());
  out.velocities = true;
  out.min_duration = 0.35;  // 0.2 s planned: held at 0.3 and 0.4 s
  const msg::JointTrajectory held = ToTrajectory(0, {"a"}, q, 0.1, out, 0);
  ASSERT_EQ(held.points.size(), 5u);
  EXPECT_NEAR(held.points[0].velocities.at(0), 2.0, 1e-9);
  EXPECT_NEAR(held.points[1].velocities.at(0), 2.0, 1e-9);
  for (std::size_t i = 2; i < 5; ++i) {
    EXPECT_EQ(held.points[i].velocities.at(0), 0.0) << i;  // the robot stops at the end and stays
    EXPECT_DOUBLE_EQ(held.points[i].positions.at(0), 0.4);
  }
}

TEST(TrajectoryStartNs, ZeroStampMeansReceipt) {
  msg::JointTrajectory t;
  EXPECT_EQ(TrajectoryStartNs(t, 42), 42);
  t.header.stamp = msg::TimeFromNanoseconds(1'700'000'000'000'000'007);
  EXPECT_EQ(TrajectoryStartNs(t, 42), 1'700'000'000'000'000'007);
}

// The static obstacles go out and come back as they were (the turn, the
// stamps, the point count), and the message keeps its size limit.
TEST(Obstacles, RoundTripKeepsEveryBoxAndTheLimit) {
  cell::ObstacleBox b;
  b.id = 7;
  b.centre = {0.55, 0.45, 0.1};
  b.orientation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  b.half_extents = {0.15, 0.1, 0.1};
  b.points = 1234;
  b.first_seen_ns = 1'700'000'000'123'456'789;
  msg::ObstacleArray m;
  ToObstacles({b}, msg::TimeFromNanoseconds(1'700'000'001'000'000'000), "world", &m);
  EXPECT_EQ(m.header.frame_id, "world");
  EXPECT_EQ(msg::ToNanoseconds(m.header.stamp), 1'700'000'001'000'000'000);
  const std::vector<cell::ObstacleBox> back = FromObstacles(m);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].id, 7u);
  EXPECT_EQ(back[0].centre, b.centre);
  EXPECT_TRUE(back[0].orientation.isApprox(b.orientation, 1e-15));
  EXPECT_EQ(back[0].half_extents, b.half_extents);
  EXPECT_EQ(back[0].points, 1234);
  EXPECT_EQ(back[0].first_seen_ns, b.first_seen_ns);
  const std::vector<cell::ObstacleBox> many(msg::Limits::kObstacles + 5, b);
  ToObstacles(many, {}, "world", &m);
  EXPECT_EQ(m.obstacles.size(), msg::Limits::kObstacles);
}

TEST(HumanPointsAdapter, RoundTripKeepsPointsMotionsAndTheLimits) {
  cell::HumanPoints p;
  p.voxel_size = 0.03;
  p.means.resize(3, 3);
  p.means << 1.0, 1.1, 1.2,  //
      0.0, 0.1, 0.2,         //
      0.3, 0.4, 0.5;
  for (int i = 0; i < 3; ++i) {
    Eigen::Matrix3d c = (1e-4 * (i + 1)) * Eigen::Matrix3d::Identity();
    c(0, 1) = c(1, 0) = 1e-5;
    p.covariances.push_back(c);
  }
  p.motion_of = {1, -1, 0};
  p.motions.push_back({Eigen::Vector3d(0.1, 0, 0), 0.01 * Eigen::Matrix3d::Identity(), 4});
  p.motions.push_back({Eigen::Vector3d(-0.4, 0.2, 0), 0.04 * Eigen::Matrix3d::Identity(), 9});
  msg::HumanPoints m;
  ToHumanPoints(p, msg::TimeFromNanoseconds(1'700'000'001'000'000'000), "world", &m);
  EXPECT_EQ(m.header.frame_id, "world");
  EXPECT_EQ(msg::ToNanoseconds(m.header.stamp), 1'700'000'001'000'000'000);
  ASSERT_EQ(m.points.size(), 3u);
  EXPECT_EQ(m.points[0].motion, 2u);  // motions[1] on the wire as k + 1
  EXPECT_EQ(m.points[1].motion, 0u);
  const cell::HumanPoints back = FromHumanPoints(m);
  EXPECT_EQ(back.voxel_size, 0.03);
  EXPECT_EQ(back.means, p.means);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(back.covariances[static_cast<std::size_t>(i)], p.covariances[static_cast<std::size_t>(i)]);
  EXPECT_EQ(back.motion_of, p.motion_of);
  ASSERT_EQ(back.motions.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(back.motions[k].id, p.motions[k].id);
    EXPECT_EQ(back.motions[k].velocity, p.motions[k].velocity);
    EXPECT_EQ(back.motions[k].covariance, p.motions[k].covariance);
  }
  // More than the wire holds: points and motions cut at the limits, and a
  // point whose motion was cut goes out untracked.
  cell::HumanPoints many;
  const int n = static_cast<int>(msg::Limits::kHumanPoints) + 5;
  many.means = Eigen::Matrix3Xd::Ones(3, n);
  many.covariances.assign(static_cast<std::size_t>(n), 1e-4 * Eigen::Matrix3d::Identity());
  many.motions.assign(msg::Limits::kPointMotions + 2, cell::PointMotion{});
  many.motion_of.assign(static_cast<std::size_t>(n), static_cast<int>(msg::Limits::kPointMotions) + 1);
  many.motion_of[0] = 0;
  ToHumanPoints(many, {}, "world", &m);
  EXPECT_EQ(m.points.size(), msg::Limits::kHumanPoints);
  EXPECT_EQ(m.motions.size(), msg::Limits::kPointMotions);
  EXPECT_EQ(m.points[0].motion, 1u);
  EXPECT_EQ(m.points[1].motion, 0u);
}

}  // namespace
}  // namespace iplan::services
