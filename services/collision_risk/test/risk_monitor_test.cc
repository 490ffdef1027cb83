// The risk monitor's verdicts from each layer, its ISO/TS 15066 arithmetic,
// and its refusal of inputs it cannot map.
#include "services/collision_risk/core/risk_monitor.h"
#include "services/collision_risk/risk_config.h"

#include <gtest/gtest.h>

#include "iplan/core/params.h"

namespace iplan::collision_risk {
namespace {

constexpr int64_t kSec = 1000000000;
const std::vector<std::string> kJoints = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l",
                                          "shoulder_r", "elbow_r", "hand_r"};
const std::vector<std::string> kRobotJoints = {"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                               "panda_joint5", "panda_joint6", "panda_joint7"};

// A person standing upright with the torso at `torso`, facing -x, arms
// forward; the right hand is `reach` m in front of the torso.
std::vector<Eigen::Vector3d> Person(const Eigen::Vector3d& torso, double reach = 0.3) {
  return {torso + Eigen::Vector3d(0, 0, 0.48), torso + Eigen::Vector3d(0, 0, 0.30), torso,
          torso + Eigen::Vector3d(0, -0.18, 0.25), torso + Eigen::Vector3d(-0.1, -0.2, 0.0),
          torso + Eigen::Vector3d(-0.25, -0.2, -0.05), torso + Eigen::Vector3d(0, 0.18, 0.25),
          torso + Eigen::Vector3d(-0.1, 0.2, 0.05), torso + Eigen::Vector3d(-reach, 0.1, 0.0)};
}

class RiskMonitorTest : public ::testing::Test {
 protected:
  RiskMonitorTest()
      : monitor_(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"),
                 collision::HumanBodyParams::DefaultUpperBody(), Params()) {}
  static RiskParams Params() {
    RiskParams p;
    p.ssm.measure_human_speed = true;
    // These cases test the layers one at a time: separation with a measured
    // speed and no prediction; the degraded mode has tests of its own.
    p.ssm.degrade_without_prediction = false;
    p.person_required = false;
    return p;
  }
  void RobotAtReady(int64_t t) {
    ASSERT_EQ(monitor_.UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  }
  void SeePerson(int64_t t, const Eigen::Vector3d& torso, double reach = 0.3) {
    ASSERT_EQ(monitor_.UpdateSkeleton(t, kJoints, Person(torso, reach)), std::nullopt);
  }
  // A prediction in which the torso moves with `velocity` from `torso`
  // (constant-velocity future), sigma growing from 3 cm by 5 cm per second.
  PredictionInput Predict(int64_t t0, const Eigen::Vector3d& torso, const Eigen::Vector3d& velocity, int steps,
                          double dt, double reach = 0.3) {
    PredictionInput p;
    p.t0_ns = t0;
    p.time_step = dt;
    p.num_steps = steps;
    p.joint_names = kJoints;
    p.actions = {"approach"};
    p.probabilities = {1.0};
    p.means.resize(1);
    p.covariances.resize(1);
    for (int k = 0; k < steps; ++k) {
      const double tau = (k + 1) * dt;
      const double sigma = 0.03 + 0.05 * tau;
      for (const auto& j : Person(torso + velocity * tau, reach)) {
        p.means[0].push_back(j);
        p.covariances[0].push_back(sigma * sigma * Eigen::Matrix3d::Identity());
      }
    }
    return p;
  }
  // A person 1.0 m in front of the robot's hand at ready, walking at it at
  // 0.8 m/s: seen 0.3 s before t and at t, predicted from t.
  void WalkAtTheHand(RiskMonitor* m, int64_t t) {
    const Eigen::Vector3d torso(1.4, 0, 0.55), v(-0.8, 0, 0);
    ASSERT_EQ(m->UpdateSkeleton(t - 3 * kSec / 10, kJoints, Person(torso - v * 0.3)), std::nullopt);
    ASSERT_EQ(m->UpdateSkeleton(t, kJoints, Person(torso)), std::nullopt);
    ASSERT_EQ(m->UpdatePrediction(Predict(t, torso, v, 15, 1.0 / 15)), std::nullopt);
  }
  RiskMonitor monitor_;
};

TEST_F(RiskMonitorTest, StopsWithoutRobotState) {
  const RiskReport r = monitor_.Evaluate(10 * kSec);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop);
  EXPECT_EQ(r.reason, "no robot state yet");
}

TEST_F(RiskMonitorTest, NoPersonSeenHasNoSeparation) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.reason;  // person_required is off here
  EXPECT_EQ(r.reason, "no person seen");
  EXPECT_FALSE(r.min_separation.has_value());
  EXPECT_FALSE(r.binding_separation.has_value());
  EXPECT_FALSE(r.separation_margin.has_value());
}

TEST_F(RiskMonitorTest, OkWhenThePersonStaysAway) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  SeePerson(t - 2 * kSec / 10, {2.0, 0, 1.0});  // within the 0.3 s speed window: measured, 0 m/s
  SeePerson(t, {2.0, 0, 1.0});
  ASSERT_EQ(monitor_.UpdatePrediction(Predict(t, {2.0, 0, 1.0}, {0, 0, 0}, 15, 1.0 / 15)), std::nullopt);
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.reason;
  EXPECT_EQ(r.reason, "clear");
  EXPECT_EQ(r.waypoint_bounds.size(), 15u);
  EXPECT_LT(r.max_bound, 1e-6);
  EXPECT_GT(r.min_separation.value(), 1.0);
  EXPECT_NEAR(r.human_speed, 0.0, 1e-9);
  EXPECT_NEAR(r.robot_speed, 0.0, 1e-9);
  // S_p = v_h (T_r + T_s) + v_r T_r + S_s + C + Z_d + Z_r with v_h = v_r = 0;
  // a robot at rest travels nothing while it stops, so S_s does not count.
  EXPECT_NEAR(r.protective_separation, 0.1 + 0.05 + 0.02, 1e-12);
  EXPECT_NEAR(r.separation_margin.value(), r.binding_separation.value() - r.protective_separation, 1e-12);
  EXPECT_GE(r.binding_separation.value(), r.min_separation.value());
}

TEST(RiskMonitorUndirected, StoppingDistanceAlwaysCounts) {
  RiskParams p;
  p.ssm.directed = false;
  p.ssm.degrade_without_prediction = false;
  RiskMonitor monitor(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"),
                      collision::HumanBodyParams::DefaultUpperBody(), p);
  const int64_t t = 100 * kSec;
  ASSERT_EQ(monitor.UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}),
            std::nullopt);
  ASSERT_EQ(monitor.UpdateSkeleton(t - 2 * kSec / 10, kJoints, Person({2.0, 0, 1.0})), std::nullopt);
  ASSERT_EQ(monitor.UpdateSkeleton(t, kJoints, Person({2.0, 0, 1.0})), std::nullopt);
  const RiskReport r = monitor.Evaluate(t);
  EXPECT_NEAR(r.protective_separation, 0.15 + 0.1 + 0.05 + 0.02, 1e-12);
  EXPECT_NEAR(r.separation_margin.value(), r.min_separation.value() - r.protective_separation, 1e-12);
}

TEST_F(RiskMonitorTest, MeasuredHumanSpeedEntersTheProtectiveSeparation) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  // Torso moving at 1 m/s towards the robot over the 0.3 s window.
  SeePerson(t - 3 * kSec / 10, {2.3, 0, 1.0});
  SeePerson(t, {2.0, 0, 1.0});
  const RiskReport r = monitor_.Evaluate(t);
  // Directed: the torso's speed towards the binding robot sphere, at most
  // 1 m/s and most of it (the person walks straight at the robot).
  EXPECT_GT(r.human_speed, 0.7);
  EXPECT_LE(r.human_speed, 1.0 + 1e-9);
  EXPECT_NEAR(r.protective_separation, r.human_speed * (0.1 + 0.3) + 0.1 + 0.05 + 0.02, 1e-9);
  EXPECT_EQ(r.reason, "clear (separation only: no current prediction)");
}

TEST_F(RiskMonitorTest, SidewaysMotionDoesNotInflateTheDirectedProtectiveSeparation) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  // The whole person moving at 1 m/s along y, 1 m in front of the robot.
  SeePerson(t - 3 * kSec / 10, {1.3, -0.3, 0.6});
  SeePerson(t, {1.3, 0.0, 0.6});
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_LT(r.human_speed, 0.3) << "only the part of the motion towards the robot counts";
  // The same scene undirected: v_h = 1 m/s and S_s, so S_p is at least 0.55 m larger.
  RiskParams p;
  p.ssm.directed = false;
  p.ssm.degrade_without_prediction = false;
  RiskMonitor undirected(collision::RobotModel(monitor_.robot()), collision::HumanBodyParams::DefaultUpperBody(), p);
  ASSERT_EQ(undirected.UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  ASSERT_EQ(undirected.UpdateSkeleton(t - 3 * kSec / 10, kJoints, Person({1.3, -0.3, 0.6})), std::nullopt);
  ASSERT_EQ(undirected.UpdateSkeleton(t, kJoints, Person({1.3, 0.0, 0.6})), std::nullopt);
  const RiskReport u = undirected.Evaluate(t);
  EXPECT_NEAR(u.human_speed, 1.0, 1e-9);
  EXPECT_NEAR(u.min_separation.value(), r.min_separation.value(), 1e-12);
  EXPECT_GT(r.separation_margin.value() - u.separation_margin.value(), 0.4 + 0.15 - 0.3 * 0.4);
}

TEST_F(RiskMonitorTest, StoppedRobotBesideAStillPersonMayMoveAwayButNotCloser) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  // A person standing still with the right hand about 0.25 m from the robot:
  // outside S_p of a robot at rest (0.17 m), inside S_p with S_s (0.32 m).
  const Eigen::Vector3d torso(0.95, 0, 0.5);
  SeePerson(t - 2 * kSec / 10, torso, 0.3);
  SeePerson(t, torso, 0.3);
  const RiskReport still = monitor_.Evaluate(t);
  ASSERT_GT(still.min_separation.value(), 0.17 + 0.02);
  ASSERT_LT(still.min_separation.value(), 0.32 - 0.02);
  EXPECT_NE(still.verdict, Verdict::kProtectiveStop) << still.reason;
  // Folding the shoulder back moves every sphere away from the person.
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 1.0},
                                      {{0, -0.785, 0, -2.356, 0, 1.571, 0.785}, {0, -1.3, 0, -2.356, 0, 1.571, 0.785}}),
            std::nullopt);
  const RiskReport away = monitor_.Evaluate(t);
  EXPECT_NEAR(away.robot_speed, 0.0, 1e-12) << "no sphere of the binding pair approaches";
  EXPECT_NEAR(away.separation_margin.value(), still.separation_margin.value(), 1e-12);
  EXPECT_NE(away.verdict, Verdict::kProtectiveStop) << away.reason;
  // Leaning the shoulder forward approaches the person: v_r T_r and S_s,
  // scaled by v_r / 1 m/s, count.
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 0.5},
                                      {{0, -0.785, 0, -2.356, 0, 1.571, 0.785}, {0, -0.3, 0, -2.356, 0, 1.571, 0.785}}),
            std::nullopt);
  const RiskReport closer = monitor_.Evaluate(t);
  EXPECT_GT(closer.robot_speed, 0.3);
  EXPECT_NEAR(closer.protective_separation,
              closer.robot_speed * 0.1 + 0.15 * std::min(1.0, closer.robot_speed / 1.0) + 0.17 + closer.human_speed * 0.4,
              1e-9);
  ASSERT_LT(closer.separation_margin.value(), 0.0);
  // Too close at that speed, not at a lower one: ISO/TS 15066 speed
  // reduction slows the robot (its path time-scaled) so that the binding
  // pair keeps S_p with what it travels while slowing to spare, instead of
  // stopping it.
  EXPECT_EQ(closer.verdict, Verdict::kSlowDown) << closer.reason;
  EXPECT_EQ(closer.reason.rfind("speed reduced to ", 0), 0u) << closer.reason;
  EXPECT_GE(closer.speed_scale, monitor_.params().ssm.min_speed_scale);
  EXPECT_LT(closer.speed_scale, 1.0);
  EXPECT_LE(safety::ProtectiveSeparationDistance(monitor_.params().ssm, closer.human_speed,
                                               closer.speed_scale * closer.robot_speed),
            closer.binding_separation.value() -
                closer.robot_speed * monitor_.params().ssm.speed_reduction_time + 1e-9);
  // Without speed reduction the same approach is stopped.
  RiskParams strict = monitor_.params();
  strict.ssm.speed_reduction = false;
  RiskMonitor m(monitor_.robot(), collision::HumanBodyParams::DefaultUpperBody(), strict);
  ASSERT_EQ(m.UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  ASSERT_EQ(m.UpdateTrajectory(t, kRobotJoints, {0.0, 0.5},
                               {{0, -0.785, 0, -2.356, 0, 1.571, 0.785}, {0, -0.3, 0, -2.356, 0, 1.571, 0.785}}),
            std::nullopt);
  for (int64_t ts : {t - 2 * kSec / 10, t}) ASSERT_EQ(m.UpdateSkeleton(ts, kJoints, Person(torso, 0.3)), std::nullopt);
  const RiskReport stopped = m.Evaluate(t);
  EXPECT_EQ(stopped.verdict, Verdict::kProtectiveStop) << stopped.reason;
  EXPECT_EQ(stopped.speed_scale, 0.0);
}

// Inside S_p, moving away is a retreat (SsmParams::retreat_speed): the
// monitor lets it run (SLOW_DOWN), where standing still or coming closer
// stops; with retreat_speed 0 every pair inside S_p stops.
TEST_F(RiskMonitorTest, InsideTheProtectiveSeparationARetreatRunsAndRestStops) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  const Eigen::Vector3d torso(0.86, 0, 0.5);  // the hand about 0.15 m from the robot, standing still
  SeePerson(t - 2 * kSec / 10, torso, 0.3);
  SeePerson(t, torso, 0.3);
  const RiskReport rest = monitor_.Evaluate(t);
  ASSERT_LT(rest.min_separation.value(), 0.17 - 0.005);
  ASSERT_GT(rest.min_separation.value(), 0.05);
  EXPECT_EQ(rest.verdict, Verdict::kProtectiveStop) << rest.reason;
  EXPECT_FALSE(rest.retreating);
  // Folding the shoulder back at about 0.5 rad/s moves the spheres away.
  const std::vector<std::vector<double>> back = {{0, -0.785, 0, -2.356, 0, 1.571, 0.785},
                                                 {0, -1.3, 0, -2.356, 0, 1.571, 0.785}};
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 1.0}, back), std::nullopt);
  const RiskReport away = monitor_.Evaluate(t);
  EXPECT_EQ(away.verdict, Verdict::kSlowDown) << away.reason;
  EXPECT_TRUE(away.retreating);
  EXPECT_EQ(away.reason.rfind("retreating: separation ", 0), 0u) << away.reason;
  EXPECT_EQ(away.separation_margin.value(), 0.0);
  // Too slow to count as a retreat (0.01 rad/s): a stop.
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 51.5}, back), std::nullopt);
  EXPECT_EQ(monitor_.Evaluate(t).verdict, Verdict::kProtectiveStop);
  // The strict reading: no retreat inside S_p.
  RiskParams strict = monitor_.params();
  strict.ssm.retreat_speed = 0.0;
  RiskMonitor m(monitor_.robot(), collision::HumanBodyParams::DefaultUpperBody(), strict);
  ASSERT_EQ(m.UpdateRobotState(t, kRobotJoints, back[0]), std::nullopt);
  ASSERT_EQ(m.UpdateTrajectory(t, kRobotJoints, {0.0, 1.0}, back), std::nullopt);
  for (int64_t ts : {t - 2 * kSec / 10, t})
    ASSERT_EQ(m.UpdateSkeleton(ts, kJoints, Person(torso, 0.3)), std::nullopt);
  const RiskReport strict_away = m.Evaluate(t);
  EXPECT_EQ(strict_away.verdict, Verdict::kProtectiveStop) << strict_away.reason;
}

TEST_F(RiskMonitorTest, StopsWhenSeparationIsBelowProtectiveDistance) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  // The robot's hand is near (0.3, 0, 0.5); a person right at it.
  SeePerson(t - kSec / 3, {0.75, 0, 0.5}, 0.35);
  SeePerson(t, {0.75, 0, 0.5}, 0.35);
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop);
  EXPECT_LT(r.separation_margin.value(), 0);
  EXPECT_LT(r.binding_separation.value(), r.protective_separation);
  EXPECT_NE(r.reason.find("below the protective separation"), std::string::npos) << r.reason;
  EXPECT_EQ(r.speed_scale, 0.0);  // a robot at rest is already inside: no speed helps
  EXPECT_EQ(r.stop_scale, 0.0);
}

TEST_F(RiskMonitorTest, PredictionOfContactSoonStopsBeforeSeparationIsViolated) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  WalkAtTheHand(&monitor_, t);
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_GT(r.separation_margin.value(), 0) << "the separation layer alone would not stop yet";
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << r.reason;
  EXPECT_GE(r.max_bound, 0.05);
  EXPECT_NE(r.reason.find("collision bound"), std::string::npos) << r.reason;
  EXPECT_FALSE(r.max_robot_link.empty());
  EXPECT_FALSE(r.max_human_segment.empty());
  EXPECT_EQ(r.max_action, "approach");
}

TEST_F(RiskMonitorTest, ViolationBeyondTheStopHorizonSlowsDown) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  const Eigen::Vector3d torso(2.4, 0, 0.55), v(-0.8, 0, 0);
  SeePerson(t - 3 * kSec / 10, torso - v * 0.3);
  SeePerson(t, torso);
  // 3 s of prediction at 0.1 s: contact is predicted after about 2 s.
  ASSERT_EQ(monitor_.UpdatePrediction(Predict(t, torso, v, 30, 0.1)), std::nullopt);
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kSlowDown) << r.reason;
  EXPECT_GT(r.max_time, 1.0);
}

TEST_F(RiskMonitorTest, ExecutingTrajectoryIsWhatIsChecked) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  const Eigen::Vector3d torso(1.15, 0.0, 0.7);
  SeePerson(t, torso);
  // The person stands still, hand 0.55 m from the robot's hand: clear while
  // the robot holds; a trajectory swinging the arm out to x = 0.78 m is not.
  ASSERT_EQ(monitor_.UpdatePrediction(Predict(t, torso, {0, 0, 0}, 15, 1.0 / 15)), std::nullopt);
  EXPECT_LT(monitor_.Evaluate(t).max_bound, 0.05);
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 1.0},
                                      {{0, -0.785, 0, -2.356, 0, 1.571, 0.785}, {0, 0.9, 0, -0.4, 0, 1.571, 0.785}}),
            std::nullopt);
  const RiskReport r = monitor_.Evaluate(t);
  EXPECT_GE(r.max_bound, 0.05) << r.reason;
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << r.reason;
}

// Bound retreat: standing still is what the bound forbids, and the
// trajectory takes the robot out of the way; one that does not is stopped.
TEST_F(RiskMonitorTest, ATrajectoryOutOfThePredictedWayIsARetreatNotAStop) {
  const int64_t t = 100 * kSec;
  RobotAtReady(t);
  WalkAtTheHand(&monitor_, t);  // contact predicted soon
  const std::vector<double> ready = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};
  // Turning the arm to the side, out of the person's path, within 0.5 s.
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 0.5}, {ready, {1.6, -0.785, 0, -2.356, 0, 1.571, 0.785}}),
            std::nullopt);
  const RiskReport aside = monitor_.Evaluate(t);
  EXPECT_GE(aside.hold_bound, 0.05) << "standing still is what the bound forbids";
  EXPECT_LE(aside.horizon_bound, aside.hold_bound - 0.05);
  EXPECT_EQ(aside.verdict, Verdict::kSlowDown) << aside.reason;
  EXPECT_TRUE(aside.retreating);
  EXPECT_EQ(aside.reason.rfind("retreating from the predicted person: ", 0), 0u) << aside.reason;
  // Reaching towards the person instead lowers nothing: a stop.
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 0.5}, {ready, {0, 0.3, 0, -1.2, 0, 1.571, 0.785}}),
            std::nullopt);
  const RiskReport towards = monitor_.Evaluate(t);
  EXPECT_EQ(towards.verdict, Verdict::kProtectiveStop) << towards.reason;
  EXPECT_FALSE(towards.retreating);
  // Half as far round (1.0 rad): the bound within the horizon stays above
  // 1 - delta_cl (about 0.9) but 0.05 below standing still's 1: a retreat
  // with the default gain, a stop with the gain 0 (off) or 0.2.
  const std::vector<std::vector<double>> half = {ready, {1.0, -0.785, 0, -2.356, 0, 1.571, 0.785}};
  ASSERT_EQ(monitor_.UpdateTrajectory(t, kRobotJoints, {0.0, 0.5}, half), std::nullopt);
  const RiskReport partial = monitor_.Evaluate(t);
  EXPECT_GE(partial.horizon_bound, 0.05);
  EXPECT_EQ(partial.verdict, Verdict::kSlowDown) << partial.reason;
  EXPECT_TRUE(partial.retreating);
  for (double gain : {0.0, 0.2}) {
    RiskParams other = monitor_.params();
    other.bound_retreat_gain = gain;
    RiskMonitor m(monitor_.robot(), collision::HumanBodyParams::DefaultUpperBody(), other);
    ASSERT_EQ(m.UpdateRobotState(t, kRobotJoints, ready), std::nullopt);
    ASSERT_EQ(m.UpdateTrajectory(t, kRobotJoints, {0.0, 0.5}, half), std::nullopt);
    WalkAtTheHand(&m, t);
    const RiskReport r = m.Evaluate(t);
    EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << "gain " << gain << ": " << r.reason;
    EXPECT_FALSE(r.retreating);
  }
}

TEST_F(RiskMonitorTest, RejectsRobotStatesOutsideTheJointLimits) {
  const std::vector<double> ready = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};
  std::vector<double> q = ready;
  q[3] = 100.0;  // panda_joint4
  const auto why = monitor_.UpdateRobotState(kSec, kRobotJoints, q);
  ASSERT_TRUE(why.has_value());
  EXPECT_EQ(why->rfind("joint state: joint 'panda_joint4' at 100 rad is outside its limits", 0), 0u) << *why;
  // The refused state is not used: with no state the verdict stays a stop.
  EXPECT_EQ(monitor_.Evaluate(kSec).reason, "no robot state yet");
  // Beyond the limit by less than the tolerance (panda_joint4 upper -0.0698 rad) is accepted.
  q[3] = -0.0698 + 0.9 * RiskParams{}.joint_limit_tolerance;
  EXPECT_EQ(monitor_.UpdateRobotState(kSec, kRobotJoints, q), std::nullopt);
  EXPECT_EQ(monitor_.UpdateRobotState(kSec, kRobotJoints, ready), std::nullopt);
}

TEST_F(RiskMonitorTest, RejectsInputsItCannotMap) {
  EXPECT_EQ(*monitor_.UpdateRobotState(0, {"j1"}, {0.0}), "joint state: missing joint 'panda_joint1'");
  EXPECT_EQ(*monitor_.UpdateSkeleton(0, {"head"}, {Eigen::Vector3d::Zero()}), "skeleton: missing joint 'neck'");
  PredictionInput p = Predict(0, {2, 0, 1}, {0, 0, 0}, 3, 0.1);
  p.covariances[0][4] = -Eigen::Matrix3d::Identity();
  ASSERT_TRUE(monitor_.UpdatePrediction(p).has_value());
  EXPECT_NE(monitor_.UpdatePrediction(p)->find("not positive definite"), std::string::npos);
  p = Predict(0, {2, 0, 1}, {0, 0, 0}, 3, 0.1);
  p.means[0].pop_back();
  EXPECT_EQ(*monitor_.UpdatePrediction(p), "prediction action 0 has the wrong number of Gaussians");
}

TEST(RiskMonitorFailSafe, NoTrackedPersonStopsTheRobot) {
  RiskMonitor monitor(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"),
                      collision::HumanBodyParams::DefaultUpperBody(), RiskParams{});
  const int64_t t = 100 * kSec;
  ASSERT_EQ(monitor.UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  RiskReport r = monitor.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop);
  EXPECT_NE(r.reason.find("no person tracked yet"), std::string::npos) << r.reason;
  ASSERT_EQ(monitor.UpdateSkeleton(t, kJoints, Person({2.5, 0, 1.0})), std::nullopt);
  EXPECT_EQ(monitor.Evaluate(t).verdict, Verdict::kOk);
  // The skeleton stream stops: after stale_after the person could be anywhere.
  ASSERT_EQ(monitor.UpdateRobotState(t + kSec, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  r = monitor.Evaluate(t + kSec);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop);
  EXPECT_NE(r.reason.find("person no longer tracked"), std::string::npos) << r.reason;
}

TEST(RiskMonitorFailSafe, WithoutAUsablePredictionSeparationUsesTheDefaultHumanSpeed) {
  RiskParams p;
  p.ssm.measure_human_speed = true;
  RiskMonitor monitor(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"),
                      collision::HumanBodyParams::DefaultUpperBody(), p);
  const int64_t t = 100 * kSec;
  ASSERT_EQ(monitor.UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  // A person standing still: measured speed 0, but no prediction says what
  // they intend, so S_p takes the ISO default speed.
  ASSERT_EQ(monitor.UpdateSkeleton(t - 3 * kSec / 10, kJoints, Person({2.0, 0, 1.0})), std::nullopt);
  ASSERT_EQ(monitor.UpdateSkeleton(t, kJoints, Person({2.0, 0, 1.0})), std::nullopt);
  const RiskReport r = monitor.Evaluate(t);
  EXPECT_DOUBLE_EQ(r.human_speed, p.ssm.default_human_speed);
  EXPECT_NEAR(r.protective_separation, 1.6 * (0.1 + 0.3) + 0.1 + 0.05 + 0.02, 1e-9);
  EXPECT_NE(r.reason.find("degraded"), std::string::npos) << r.reason;
}

TEST(RiskSettings, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(RiskSettings{})),
            "");
}

// Several people: the bound is the union over persons, the separation the
// nearest person's.
class RiskMonitorPeopleTest : public RiskMonitorTest {
 protected:
  static RiskMonitor Make() {
    return RiskMonitor(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"),
                       collision::HumanBodyParams::DefaultUpperBody(), Params());
  }
  // Person `id` with torso `torso` walking at `v`, seen and predicted at t into `m`.
  void Add(RiskMonitor* m, cell::BodyId id, int64_t t, const Eigen::Vector3d& torso, const Eigen::Vector3d& v) {
    ASSERT_EQ(m->UpdateSkeleton(id, t - 3 * kSec / 10, kJoints, Person(torso - v * 0.3)), std::nullopt);
    ASSERT_EQ(m->UpdateSkeleton(id, t, kJoints, Person(torso)), std::nullopt);
    ASSERT_EQ(m->UpdatePrediction(id, Predict(t, torso, v, 30, 0.1)), std::nullopt);
  }
  static void Ready(RiskMonitor* m, int64_t t) {
    ASSERT_EQ(m->UpdateRobotState(t, kRobotJoints, {0, -0.785, 0, -2.356, 0, 1.571, 0.785}), std::nullopt);
  }
};

TEST_F(RiskMonitorPeopleTest, BoundIsTheSumOfEachPersonsBoundCappedAtOne) {
  const int64_t t = 100 * kSec;
  const Eigen::Vector3d a(1.6, 0.25, 0.55), va(-0.6, 0, 0), b(1.8, -0.3, 0.6), vb(-0.5, 0.1, 0);
  RiskMonitor only_a = Make(), only_b = Make(), both = Make();
  for (RiskMonitor* m : {&only_a, &only_b, &both}) Ready(m, t);
  Add(&only_a, 1, t, a, va);
  Add(&only_b, 2, t, b, vb);
  Add(&both, 1, t, a, va);
  Add(&both, 2, t, b, vb);
  const RiskReport ra = only_a.Evaluate(t), rb = only_b.Evaluate(t), r = both.Evaluate(t);
  EXPECT_EQ(r.num_people, 2);
  EXPECT_EQ(r.num_predicted, 2);
  ASSERT_EQ(r.waypoint_bounds.size(), ra.waypoint_bounds.size());
  ASSERT_EQ(r.waypoint_bounds.size(), rb.waypoint_bounds.size());
  int summed = 0, capped = 0;
  for (std::size_t w = 0; w < r.waypoint_bounds.size(); ++w) {
    const double sum = ra.waypoint_bounds[w] + rb.waypoint_bounds[w];
    EXPECT_NEAR(r.waypoint_bounds[w], std::min(1.0, sum), 1e-12) << "waypoint " << w;
    summed += ra.waypoint_bounds[w] > 1e-3 && rb.waypoint_bounds[w] > 1e-3 && sum < 1;
    capped += sum > 1;
  }
  EXPECT_GT(summed, 0) << "a waypoint where both persons contribute and the sum is below 1";
  EXPECT_GT(capped, 0) << "a waypoint where the sum is capped";
  EXPECT_LE(r.max_bound, std::min(1.0, ra.max_bound + rb.max_bound) + 1e-12);
  EXPECT_GE(r.max_bound, std::max(ra.max_bound, rb.max_bound));
  // Separation: the nearer person's.
  EXPECT_NEAR(r.min_separation.value(), std::min(ra.min_separation.value(), rb.min_separation.value()), 1e-12);
  EXPECT_NEAR(r.separation_margin.value(), std::min(ra.separation_margin.value(), rb.separation_margin.value()), 1e-12);
}

TEST_F(RiskMonitorPeopleTest, AnOlderPredictionIsTakenAtItsStepNearestToEachWaypoint) {
  // Body 1's prediction is one step (0.1 s) older than body 2's: the
  // waypoints are body 2's (t + (w + 1) 0.1 s), where body 1's step w + 1
  // falls (its last step beyond its end).
  const int64_t t = 100 * kSec;
  const Eigen::Vector3d a(1.6, 0.25, 0.55), va(-0.6, 0, 0), b(1.8, -0.3, 0.6), vb(-0.5, 0.1, 0);
  RiskMonitor only_b = Make(), both = Make();
  for (RiskMonitor* m : {&only_b, &both}) Ready(m, t);
  Add(&both, 2, t, a, va);
  for (RiskMonitor* m : {&only_b, &both}) {
    ASSERT_EQ(m->UpdateSkeleton(1, t, kJoints, Person(b)), std::nullopt);
    ASSERT_EQ(m->UpdatePrediction(1, Predict(t - kSec / 10, b - vb * 0.1, vb, 30, 0.1)), std::nullopt);
  }
  RiskMonitor only_a = Make();
  Ready(&only_a, t);
  Add(&only_a, 2, t, a, va);
  const RiskReport ra = only_a.Evaluate(t), rb = only_b.Evaluate(t), r = both.Evaluate(t);
  EXPECT_EQ(r.prediction_stamp_ns, t) << "the newest prediction gives the waypoints";
  ASSERT_EQ(r.waypoint_bounds.size(), 30u);
  ASSERT_EQ(rb.waypoint_bounds.size(), 30u);  // its steps at t + k 0.1 s, k = 0..29
  EXPECT_NEAR(rb.waypoint_times[1], r.waypoint_times[0], 1e-9);
  for (std::size_t w = 0; w < 30; ++w) {
    const double b_at = rb.waypoint_bounds[std::min<std::size_t>(w + 1, 29)];
    EXPECT_NEAR(r.waypoint_bounds[w], std::min(1.0, ra.waypoint_bounds[w] + b_at), 1e-12) << "waypoint " << w;
  }
  EXPECT_GT(rb.max_bound, 1e-3);
}

TEST_F(RiskMonitorPeopleTest, ASecondPersonCloseStopsThoughTheFirstIsFarAway) {
  const int64_t t = 100 * kSec;
  RiskMonitor m = Make();
  Ready(&m, t);
  Add(&m, 1, t, {2.5, 0, 1.0}, {0, 0, 0});
  const RiskReport far = m.Evaluate(t);
  EXPECT_EQ(far.verdict, Verdict::kOk) << far.reason;
  Add(&m, 7, t, {1.4, 0, 0.55}, {-0.8, 0, 0});  // walking at the robot's hand
  const RiskReport r = m.Evaluate(t);
  EXPECT_EQ(r.verdict, Verdict::kProtectiveStop) << r.reason;
  EXPECT_EQ(r.max_body_id, 7u);
  EXPECT_NE(r.reason.find("body 7 of 2"), std::string::npos) << r.reason;
  EXPECT_LT(r.min_separation.value(), far.min_separation.value() - 0.5);
}

TEST_F(RiskMonitorPeopleTest, OutOfOrderAndStalePredictionsOfABodyAreNotUsed) {
  const int64_t t = 100 * kSec;
  RiskMonitor m = Make();
  Ready(&m, t);
  Add(&m, 1, t, {2.5, 0, 1.0}, {0, 0, 0});
  // Body 1's older prediction does not replace its newer one.
  const auto late = m.UpdatePrediction(1, Predict(t - kSec / 10, {1.4, 0, 0.55}, {-0.8, 0, 0}, 30, 0.1));
  ASSERT_TRUE(late);
  EXPECT_NE(late->find("out of order"), std::string::npos) << *late;
  EXPECT_LT(m.Evaluate(t).max_bound, 1e-6);
  // A close person whose newest prediction is older than stale_after (0.5 s)
  // is not in the bound; with no skeleton either, not in the separation.
  ASSERT_EQ(m.UpdatePrediction(2, Predict(t - 6 * kSec / 10, {1.4, 0, 0.55}, {-0.8, 0, 0}, 30, 0.1)), std::nullopt);
  const RiskReport r = m.Evaluate(t);
  EXPECT_EQ(r.num_predicted, 1);
  EXPECT_EQ(r.num_people, 1);
  EXPECT_LT(r.max_bound, 1e-6);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.reason;
}

}  // namespace
}  // namespace iplan::collision_risk
