#include <gtest/gtest.h>

#include "iplan/cell/joint_trajectory.h"
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
