#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "iplan/planning/kinematics.h"
#include "test_util.h"

namespace iplan::planning {
namespace {

TEST(Kinematics, PointJacobianMatchesFiniteDifferences) {
  const collision::RobotModel robot = testing::LoadPanda();
  KinematicChains chains(robot);
  collision::RobotData d(robot), d2(robot);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q = 0.5 * (robot.LowerLimits() + robot.UpperLimits());
    for (int j = 0; j < robot.nq; ++j) q[j] += u(rng);
    collision::CalcForwardKinematics(robot, q, &d);
    for (std::size_t s = 0; s < robot.spheres.size(); s += 3) {
      const int link = robot.spheres[s].link;
      Eigen::Matrix<double, 3, Eigen::Dynamic> J(3, robot.nq);
      chains.CalcPointJacobian(d, link, d.p_WS.col(s), J);
      for (int j = 0; j < robot.nq; ++j) {
        Eigen::VectorXd qp = q;
        qp[j] += 1e-6;
        collision::CalcForwardKinematics(robot, qp, &d2);
        const Eigen::Vector3d fd = (d2.p_WS.col(s) - d.p_WS.col(s)) / 1e-6;
        EXPECT_LT((fd - J.col(j)).norm(), 1e-5) << "sphere " << s << " joint " << j;
      }
    }
  }
}

TEST(Kinematics, IkReachesAReachablePoseAndFailsOnAnUnreachableOne) {
  const collision::RobotModel robot = testing::LoadPanda();
  KinematicChains chains(robot);
  const int flange = robot.FindLink("panda_link8");
  ASSERT_GE(flange, 0);
  // A target produced by FK is reachable by construction.
  Eigen::VectorXd q_true(7);
  q_true << 0.3, 0.2, -0.1, -1.9, 0.1, 2.0, 0.5;
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, q_true, &d);
  const Eigen::Isometry3d X_target = d.X_WL[flange];
  Eigen::VectorXd seed(7);
  seed << 0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8;
  IkOptions opt;
  std::mt19937_64 rng(1);
  const IkResult r = SolveIk(chains, flange, Eigen::Vector3d::Zero(), X_target, seed, opt, &rng);
  ASSERT_TRUE(r.success) << r.position_error << " " << r.orientation_error;
  collision::CalcForwardKinematics(robot, r.q, &d);
  EXPECT_LT((d.X_WL[flange].translation() - X_target.translation()).norm(), 1e-4);
  EXPECT_LT(Eigen::AngleAxisd(d.X_WL[flange].linear() * X_target.linear().transpose()).angle(), 1e-3);
  for (int j = 0; j < 7; ++j) {
    EXPECT_GE(r.q[j], robot.LowerLimits()[j]);
    EXPECT_LE(r.q[j], robot.UpperLimits()[j]);
  }
  // 2 m away: beyond the arm's reach (about 0.85 m).
  Eigen::Isometry3d far = X_target;
  far.translation() = Eigen::Vector3d(2.0, 0.0, 0.5);
  opt.restarts = 2;
  const IkResult f = SolveIk(chains, flange, Eigen::Vector3d::Zero(), far, seed, opt, &rng);
  EXPECT_FALSE(f.success);
  EXPECT_GT(f.position_error, 0.5);
}

TEST(Kinematics, IkForAToolAxisLeavesTheTurnAboutItFree) {
  const collision::RobotModel robot = testing::LoadPanda();
  KinematicChains chains(robot);
  const int flange = robot.FindLink("panda_link8");
  Eigen::VectorXd seed(7);
  seed << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
  collision::RobotData d(robot);
  // A target whose orientation turns 1.2 rad about the flange axis away from
  // the seed's, the axis tilted: asked for the axis only, the solution may
  // keep its own turn; asked for the whole orientation, it must turn.
  collision::CalcForwardKinematics(robot, seed, &d);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.1, -1.0).normalized();
  Eigen::Isometry3d X_target = Eigen::Isometry3d::Identity();
  X_target.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix() *
                      Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_target.translation() = Eigen::Vector3d(0.5, 0.1, 0.35);
  IkOptions opt;
  opt.align_axis_L = Eigen::Vector3d::UnitZ();
  std::mt19937_64 rng(3);
  const IkResult r = SolveIk(chains, flange, Eigen::Vector3d::Zero(), X_target, seed, opt, &rng);
  ASSERT_TRUE(r.success) << r.position_error << " " << r.orientation_error;
  collision::CalcForwardKinematics(robot, r.q, &d);
  EXPECT_LT((d.X_WL[flange].translation() - X_target.translation()).norm(), 1e-4);
  EXPECT_LT(std::acos(std::min(1.0, d.X_WL[flange].linear().col(2).dot(axis))), 1e-3);
  // The turn about the axis is not the target's (it was free).
  const double full = Eigen::AngleAxisd(d.X_WL[flange].linear() * X_target.linear().transpose()).angle();
  EXPECT_GT(full, 0.05);
  opt.align_axis_L = Eigen::Vector3d(0.0, 0.0, 2.0);
  EXPECT_THROW(SolveIk(chains, flange, Eigen::Vector3d::Zero(), X_target, seed, opt, &rng), std::invalid_argument);
}

TEST(Kinematics, IkRejectsBadInput) {
  const collision::RobotModel robot = testing::LoadPanda();
  KinematicChains chains(robot);
  std::mt19937_64 rng(1);
  EXPECT_THROW(SolveIk(chains, 8, Eigen::Vector3d::Zero(), Eigen::Isometry3d::Identity(),
                       Eigen::VectorXd::Zero(6), IkOptions{}, &rng),
               std::invalid_argument);
}

}  // namespace
}  // namespace iplan::planning
