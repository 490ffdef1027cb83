// The risk monitor with a person seen only as depth points
// (RiskMonitor::UpdateHumanPoints, risk_points.cc): the separation and S_p
// numbers, the bound's growth, and what counts as a tracked person.
#include <gtest/gtest.h>

#include <iostream>

#include "services/collision_risk/core/risk_monitor.h"

namespace iplan::collision_risk {
namespace {

constexpr int64_t kSec = 1000000000;
const std::vector<std::string> kRobotJoints = {"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                               "panda_joint5", "panda_joint6", "panda_joint7"};
const std::vector<double> kReady = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};

// The measured speeds switched on (human_points.tracked_speeds; off by
// default, see ShippedDefaultJudgesATrackedPointAtTheIsoSpeed).
RiskParams WithTrackedSpeeds(bool on = true) {
  RiskParams p;
  p.human_points.tracked_speeds = on;
  return p;
}

class RiskPointsTest : public ::testing::Test {
 protected:
  explicit RiskPointsTest(const RiskParams& params = WithTrackedSpeeds())
      : robot_(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml")),
        monitor_(robot_, collision::HumanBodyParams::DefaultUpperBody(), params) {
    collision::RobotData d(robot_);
    Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(kReady.data(), 7);
    collision::CalcForwardKinematics(robot_, q, &d);
    spheres_ = d.p_WS;
    // The sphere whose surface reaches furthest along +x (towards the person).
    for (int k = 0; k < spheres_.cols(); ++k)
      if (front_ < 0 || spheres_(0, k) + robot_.spheres[k].radius > spheres_(0, front_) + robot_.spheres[front_].radius)
        front_ = k;
  }
  void RobotAtReady(int64_t t) { ASSERT_EQ(monitor_.UpdateRobotState(t, kRobotJoints, kReady), std::nullopt); }
  // Points (sigma `sigma`, voxel 1 cm: r_p = 5 mm) in front of the front
  // sphere: the first `gap` m from its surface along +x (so no other sphere
  // is nearer), the others 1 m further on, spread over 0.4 m x 0.4 m.
  void SeePoints(int64_t t, double gap, int n = 1, double sigma = 0.005) {
    const Eigen::Vector3d c = spheres_.col(front_);
    Eigen::Matrix3Xd mu(3, n);
    mu.col(0) = c + Eigen::Vector3d(robot_.spheres[front_].radius + 0.005 + gap, 0, 0);
    for (int i = 1; i < n; ++i)
      mu.col(i) = mu.col(0) + Eigen::Vector3d(1.0, 0.4 * (i % 10) / 9.0 - 0.2, 0.4 * (i / 10 % 10) / 9.0 - 0.2);
    ASSERT_EQ(monitor_.UpdateHumanPoints(t, 0.01, mu, std::vector<Eigen::Matrix3d>(n, sigma * sigma * Eigen::Matrix3d::Identity())),
              std::nullopt);
  }
  // One point `gap` m in front of the front sphere (sigma 5 mm), tracked
  // with velocity v (m/s) and isotropic velocity std sigma_v (m/s).
  void SeeTrackedPoint(int64_t t, double gap, const Eigen::Vector3d& v, double sigma_v) {
    cell::HumanPoints p;
    p.stamp_ns = t;
    p.voxel_size = 0.01;
    p.means.resize(3, 1);
    p.means.col(0) = spheres_.col(front_) + Eigen::Vector3d(robot_.spheres[front_].radius + 0.005 + gap, 0, 0);
    p.covariances = {2.5e-5 * Eigen::Matrix3d::Identity()};
    p.motion_of = {0};
    p.motions.push_back({v, sigma_v * sigma_v * Eigen::Matrix3d::Identity()});
    ASSERT_EQ(monitor_.UpdateHumanPoints(p), std::nullopt);
  }
  collision::RobotModel robot_;
  RiskMonitor monitor_;
  Eigen::Matrix3Xd spheres_;
  int front_ = -1;
};

TEST_F(RiskPointsTest, PointsAtAKnownDistanceGiveTheSeparationAndSp) {
  // A still robot (v_r = 0: S_s = 0) and points without a speed (v_h = 1.6
  // m/s): S_p = 1.6 (0.1 + 0.3) + 0.1 + 0.05 + 0.02 = 0.81 m.
  const int64_t t = 100 * kSec;
  struct Case {
    double gap;
    Verdict verdict;
  };
  for (const Case c : {Case{1.2, Verdict::kOk}, Case{0.9, Verdict::kSlowDown}, Case{0.4, Verdict::kProtectiveStop}}) {
    SCOPED_TRACE("gap " + std::to_string(c.gap));
    RobotAtReady(t);
    SeePoints(t, c.gap, 100);
    const RiskReport r = monitor_.Evaluate(t + kSec / 100);
    ASSERT_TRUE(r.min_separation.has_value()) << r.reason;
    EXPECT_NEAR(*r.min_separation, c.gap, 1e-9);
    EXPECT_EQ(r.separation_human_segment, "points");
    EXPECT_NEAR(r.protective_separation, 0.81, 1e-12);
    EXPECT_DOUBLE_EQ(r.human_speed, 1.6);
    EXPECT_DOUBLE_EQ(r.robot_speed, 0.0);
    EXPECT_NEAR(*r.separation_margin, c.gap - 0.81, 1e-9);
    EXPECT_EQ(r.verdict, c.verdict) << r.reason;
  }
}

TEST_F(RiskPointsTest, TheBoundGrowsAsThePointsApproach) {
  const int64_t t = 100 * kSec;
  double previous = 0;
  // One point, sigma 1 cm: bounds about 1e-6, 3e-4, 0.02, 0.16.
  for (double gap : {0.06, 0.05, 0.04, 0.035}) {
    SCOPED_TRACE("gap " + std::to_string(gap));
    RobotAtReady(t);
    SeePoints(t, gap, 1, 0.01);
    const RiskReport r = monitor_.Evaluate(t);
    ASSERT_EQ(r.waypoint_bounds.size(), 15u);  // 1.5 s horizon at 0.1 s
    EXPECT_DOUBLE_EQ(r.waypoint_times.front(), 0.1);
    EXPECT_EQ(r.max_human_segment, "points");
    EXPECT_EQ(r.prediction_stamp_ns, 0);
    EXPECT_GT(r.max_bound, previous);
    previous = r.max_bound;
  }
  EXPECT_GT(previous, 0.05);  // 3.5 cm at 1 cm noise: far from negligible
}

TEST_F(RiskPointsTest, FreshPointsCountAsATrackedPersonStaleOnesDoNot) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  RiskReport r = monitor_.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop);  // person_required, nothing seen
  EXPECT_EQ(r.reason.rfind("no person tracked yet", 0), 0u) << r.reason;
  // The camera sees nobody: an empty, fresh set of points.
  ASSERT_EQ(monitor_.UpdateHumanPoints(t, 0.01, Eigen::Matrix3Xd(3, 0), {}), std::nullopt);
  r = monitor_.Evaluate(t + kSec / 10);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.reason;
  EXPECT_EQ(r.reason, "no person seen (depth: no points)");
  EXPECT_FALSE(r.min_separation.has_value());
  SeePoints(t, 1.5);
  RobotAtReady(t + kSec);
  r = monitor_.Evaluate(t + kSec);  // the points are 1 s old (stale_after 0.5 s)
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop);
  EXPECT_EQ(r.reason.rfind("person no longer tracked", 0), 0u) << r.reason;
}

TEST_F(RiskPointsTest, BadPointsAreRefusedAndLeaveTheLastGoodOnes) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  SeePoints(t, 1.2, 50);
  Eigen::Matrix3Xd mu = Eigen::Matrix3Xd::Constant(3, 1, 5.0);
  auto why = monitor_.UpdateHumanPoints(t, 0.01, mu, {-1e-4 * Eigen::Matrix3d::Identity()});
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("not positive definite"), std::string::npos) << *why;
  EXPECT_NE(monitor_.UpdateHumanPoints(t, -1.0, mu, {1e-4 * Eigen::Matrix3d::Identity()}), std::nullopt);
  RiskReport r = monitor_.Evaluate(t);
  ASSERT_TRUE(r.min_separation.has_value());
  EXPECT_NEAR(*r.min_separation, 1.2, 1e-9);
  // Noise-free points (zero covariance, semi-definite) get the 1 mm floor.
  EXPECT_EQ(monitor_.UpdateHumanPoints(t, 0.01, mu, {Eigen::Matrix3d::Zero()}), std::nullopt);
  r = monitor_.Evaluate(t);
  EXPECT_GT(*r.min_separation, 4.0);
}

// Issue 29: a tracked point is judged at its measured speed towards the
// robot plus speed_sigmas (2) standard deviations; an untracked one at the
// ISO default. Still robot (S_s = 0): S_p = v_h 0.4 + 0.17 m.
TEST_F(RiskPointsTest, ATrackedSlowPersonGivesASmallSpAnUntrackedOneTheDefault) {
  const int64_t t = 100 * kSec;
  struct Case {
    const char* what;
    Eigen::Vector3d v;  // the point's velocity; +x is away from the robot
    double sigma_v;
    double v_h;
    Verdict verdict;
  };
  const Case cases[] = {
      {"still, tracked", Eigen::Vector3d::Zero(), 0.1, 0.2, Verdict::kSlowDown},  // S_p 0.25: within the 0.2 m margin
      {"walking away", Eigen::Vector3d(0.5, 0, 0), 0.1, 0.0, Verdict::kOk},       // S_p 0.17
      {"coming at 1 m/s", Eigen::Vector3d(-1.0, 0, 0), 0.1, 1.2, Verdict::kProtectiveStop},  // S_p 0.65
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    RobotAtReady(t);
    SeeTrackedPoint(t, 0.4, c.v, c.sigma_v);
    const RiskReport r = monitor_.Evaluate(t + kSec / 100);
    ASSERT_TRUE(r.min_separation.has_value()) << r.reason;
    EXPECT_NEAR(*r.min_separation, 0.4, 1e-9);
    EXPECT_NEAR(r.human_speed, c.v_h, 1e-9);
    EXPECT_NEAR(r.protective_separation, 0.4 * c.v_h + 0.17, 1e-9);
    EXPECT_EQ(r.verdict, c.verdict) << r.reason;
  }
  // Sideways at 1 m/s: towards the front sphere only its 2 sigma; towards
  // spheres beside it, part of the 1 m/s (the pair with the smallest margin binds).
  RobotAtReady(t);
  SeeTrackedPoint(t, 0.4, Eigen::Vector3d(0, 1.0, 0), 0.1);
  const RiskReport side = monitor_.Evaluate(t + kSec / 100);
  EXPECT_GE(side.human_speed, 0.2);
  EXPECT_LT(side.human_speed, 1.2);
  RobotAtReady(t);
  SeePoints(t, 0.4);  // the same point, not tracked: 1.6 m/s, S_p 0.81
  const RiskReport r = monitor_.Evaluate(t + kSec / 100);
  EXPECT_DOUBLE_EQ(r.human_speed, 1.6);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << r.reason;
}

// Shipped default (tracked_speeds false): a tracked slow point counts as
// untracked, at the ISO default speed, and the bound does not move it.
class RiskPointsDefaultTest : public RiskPointsTest {
 protected:
  RiskPointsDefaultTest() : RiskPointsTest(RiskParams{}) {}
};
TEST_F(RiskPointsDefaultTest, ShippedDefaultJudgesATrackedPointAtTheIsoSpeed) {
  EXPECT_FALSE(RiskParams{}.human_points.tracked_speeds);
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  SeeTrackedPoint(t, 0.4, Eigen::Vector3d::Zero(), 0.1);
  const RiskReport r = monitor_.Evaluate(t + kSec / 100);
  ASSERT_TRUE(r.min_separation.has_value()) << r.reason;
  EXPECT_DOUBLE_EQ(r.human_speed, 1.6);
  EXPECT_NEAR(r.protective_separation, 0.4 * 1.6 + 0.17, 1e-9);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << r.reason;
  EXPECT_NE(r.max_action, "as seen, moving");
}

// A robot sphere moving at 0.5 m/s towards a point 0.28 m away: a tracked
// still point (v_h 0.02 m/s) leaves room to slow down (ISO/TS 15066 speed
// reduction), an untracked one (1.6 m/s) does not.
TEST(PointsSeparation, ATrackedPointLetsTheRobotSlowDownAnUntrackedOneStopsIt) {
  cell::HumanPoints seen;
  seen.means.resize(3, 1);
  seen.means.col(0) = Eigen::Vector3d(0.28 + 0.1 + 0.005, 0, 0);
  seen.covariances = {1e-6 * Eigen::Matrix3d::Identity()};
  collision::GaussianPoints points;
  ASSERT_EQ(points.Set(seen.means, seen.covariances, 0.005), std::nullopt);
  const Eigen::Matrix3Xd p_WS = Eigen::Matrix3Xd::Zero(3, 1);
  Eigen::Matrix3Xd v_WS(3, 1);
  v_WS.col(0) = Eigen::Vector3d(0.5, 0, 0);
  const safety::SsmParams ssm;
  cell::HumanPoints tracked = seen;
  tracked.motion_of = {0};
  tracked.motions.push_back({Eigen::Vector3d::Zero(), 1e-4 * Eigen::Matrix3d::Identity()});
  const PointsSeparation a = EvaluatePointsSeparation(points, tracked, p_WS, {0.1}, v_WS, ssm, 2.0);
  EXPECT_NEAR(a.binding_separation, 0.28, 1e-12);
  EXPECT_NEAR(a.human_speed, 0.02, 1e-12);
  EXPECT_NEAR(a.robot_speed, 0.5, 1e-12);
  EXPECT_TRUE(a.binding_tracked);
  EXPECT_LT(a.margin(), 0.0);
  // S_p grows by 0.25 s per m/s of robot speed: room (0.28 - 0.178) / 0.25 = 0.408 m/s.
  EXPECT_NEAR(a.stop_scale, 0.408 / 0.5, 1e-9);
  EXPECT_NEAR(a.slow_scale, (0.28 - 0.05 - 0.178) / 0.25 / 0.5, 1e-9);
  const PointsSeparation b = EvaluatePointsSeparation(points, seen, p_WS, {0.1}, v_WS, ssm, 2.0);
  EXPECT_DOUBLE_EQ(b.human_speed, 1.6);
  EXPECT_FALSE(b.binding_tracked);
  EXPECT_DOUBLE_EQ(b.stop_scale, 0.0);
}

// The bound's prediction moves a tracked point at its velocity: one coming
// at the robot raises the bound of later waypoints, one going away lowers it.
TEST_F(RiskPointsTest, TheBoundMovesTrackedPointsWithTheirVelocity) {
  const int64_t t = 100 * kSec;
  auto bound = [&](const Eigen::Vector3d& v) {
    RobotAtReady(t);
    SeeTrackedPoint(t, 0.15, v, 0.05);
    const RiskReport r = monitor_.Evaluate(t);
    EXPECT_EQ(r.max_action, "as seen, moving");
    return r.max_bound;
  };
  const double coming = bound(Eigen::Vector3d(-0.5, 0, 0)), still = bound(Eigen::Vector3d::Zero()),
               going = bound(Eigen::Vector3d(0.5, 0, 0));
  std::cout << "bound, point 0.15 m away: coming at 0.5 m/s " << coming << ", still " << still << ", going " << going
            << "\n";
  EXPECT_GT(coming, 0.05);  // it reaches the robot within motion_horizon (0.5 s)
  EXPECT_GT(coming, 10 * still);
  EXPECT_LE(going, still);
}

TEST_F(RiskPointsTest, MotionsThatDoNotFitThePointsAreRefused) {
  cell::HumanPoints p;
  p.stamp_ns = 100 * kSec;
  p.means = Eigen::Matrix3Xd::Constant(3, 2, 1.0);
  p.covariances.assign(2, 1e-4 * Eigen::Matrix3d::Identity());
  p.motion_of = {0, 1};
  p.motions.push_back({Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()});
  EXPECT_EQ(monitor_.UpdateHumanPoints(p), "human points: point 1 names motion 1 of 1");
  p.motion_of = {0, -1};
  EXPECT_EQ(monitor_.UpdateHumanPoints(p), std::nullopt);
}

// The bound retreat (issue 25) holds for a person seen only as points too:
// a hand held still 2 cm from the arm's front (bound 1 standing still) and
// a trajectory that pulls the arm back over 0.6 s (bound 0.27 at 0.1 s,
// then nothing): let go, slowed, not stopped by the bound; with the gain 0
// (off) the bound stops it, as it did before points had the retreat.
TEST_F(RiskPointsTest, ATrajectoryPullingBackFromThePointsIsARetreatNotAStop) {
  const int64_t t = 100 * kSec;
  const std::vector<double> back = {0, -1.3, 0, -2.9, 0, 2.2, 0.785};
  collision::RobotData d(robot_);
  collision::CalcForwardKinematics(robot_, Eigen::Map<const Eigen::VectorXd>(back.data(), 7), &d);
  ASSERT_LT(d.p_WS(0, front_), spheres_(0, front_) - 0.08) << "the front sphere pulls back by 8 cm";
  for (double gain : {0.05, 0.0}) {
    SCOPED_TRACE("gain " + std::to_string(gain));
    RiskParams params = WithTrackedSpeeds();
    params.bound_retreat_gain = gain;
    RiskMonitor m(robot_, collision::HumanBodyParams::DefaultUpperBody(), params);
    ASSERT_EQ(m.UpdateRobotState(t, kRobotJoints, kReady), std::nullopt);
    ASSERT_EQ(m.UpdateTrajectory(t, kRobotJoints, {0.0, 0.6}, {kReady, back}), std::nullopt);
    // A hand held still 2 cm in front (sigma 1 cm), tracked: the
    // separation layer sees the arm pull back (a retreat inside S_p).
    cell::HumanPoints p;
    p.stamp_ns = t;
    p.voxel_size = 0.01;
    p.means = spheres_.col(front_) + Eigen::Vector3d(robot_.spheres[front_].radius + 0.005 + 0.02, 0, 0);
    p.covariances = {1e-4 * Eigen::Matrix3d::Identity()};
    p.motion_of = {0};
    p.motions.push_back({Eigen::Vector3d::Zero(), 1e-4 * Eigen::Matrix3d::Identity()});
    ASSERT_EQ(m.UpdateHumanPoints(p), std::nullopt);
    const RiskReport r = m.Evaluate(t);
    EXPECT_EQ(r.max_human_segment, "points");
    if (gain > 0) {
      EXPECT_GE(r.hold_bound, 1 - params.delta_cl) << "standing still is what the bound forbids";
      EXPECT_LE(r.horizon_bound, r.hold_bound - gain);
      EXPECT_EQ(r.verdict, Verdict::kSlowDown) << r.reason;
      EXPECT_TRUE(r.retreating) << r.reason;
      EXPECT_EQ(r.reason.rfind("retreating from the predicted person: ", 0), 0u) << r.reason;
    } else {
      EXPECT_EQ(r.hold_bound, 0.0);
      EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << r.reason;
    }
  }
}

}  // namespace
}  // namespace iplan::collision_risk
