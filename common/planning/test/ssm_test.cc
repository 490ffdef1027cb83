// The planner predicts the separation monitor (PlannerParams::predict_ssm):
// plans are checked here against the monitor's ISO/TS 15066 pair rule
// (safety::SsmPairRule) waypoint by waypoint, independently of the planner's
// own bookkeeping.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <gtest/gtest.h>

#include "iplan/safety/ssm.h"
#include "iplan/planning/planner.h"
#include "test_util.h"

namespace iplan::planning {
namespace {

using testing::DownOrientation;
using testing::Ready;

// One hand sphere (radius 5 cm) of one action, at `at(k)` at step k (0.1 s apart).
template <class F>
collision::HumanPrediction Hand(int steps, F at, double probability = 1.0) {
  collision::HumanPrediction hand(1, steps, {0.05});
  hand.set_action_probability(0, probability);
  for (int k = 0; k < steps; ++k) EXPECT_TRUE(hand.SetSphere(0, k, 0, at(k), 0.0004 * Eigen::Matrix3d::Identity()));
  hand.UpdateSummaries();
  return hand;
}

// The smallest monitor margin d - S_p over the waypoints 1 .. last of Q
// against the hand (action 0) whose step k is at waypoint k; pairs whose
// robot sphere moves away at `retreat` m/s or faster are left out.
// With `stop_scale`, the smallest of the pairs' stop scales instead (the
// fraction of its speed at which the monitor lets the robot go on; below
// min_speed_scale it stops it).
// `allowance` (m/s) is added to the hand's speed straight at each robot
// sphere, as collision risk adds a depth point's velocity uncertainty (or
// the ISO speed for a point not tracked).
double MonitorMargin(const collision::RobotModel& robot, const Eigen::MatrixXd& Q, double dt,
                     const collision::HumanPrediction& hand, const safety::SsmParams& ssm, int last, double retreat,
                     bool stop_scale = false, double allowance = 0.0) {
  double worst = std::numeric_limits<double>::infinity();
  collision::RobotData d0(robot), d1(robot);
  for (int i = 1; i <= std::min<int>(last, static_cast<int>(Q.cols()) - 1); ++i) {
    collision::CalcForwardKinematics(robot, Q.col(i), &d0);
    collision::CalcForwardKinematics(robot, Q.col(std::min<Eigen::Index>(i + 1, Q.cols() - 1)), &d1);
    const int k = std::min(i, hand.num_steps() - 2);
    const Eigen::Vector3d mu = hand.sphere(0, std::min(i, hand.num_steps() - 1), 0).mean;
    const Eigen::Vector3d v_h = (hand.sphere(0, k + 1, 0).mean - hand.sphere(0, k, 0).mean) / dt;
    for (int s = 0; s < static_cast<int>(robot.spheres.size()); ++s) {
      const Eigen::Vector3d delta = d0.p_WS.col(s) - mu;
      const Eigen::Vector3d v_r = (d1.p_WS.col(s) - d0.p_WS.col(s)) / dt;
      if (v_r.dot(delta.normalized()) >= retreat) continue;
      const safety::SsmPair pair =
          safety::SsmPairRule(ssm, delta, robot.spheres[s].radius + 0.05, v_h + allowance * delta.normalized(), v_r);
      worst = std::min(worst, stop_scale ? pair.stop_scale : pair.margin);
    }
  }
  return worst;
}

class PredictedMonitorTest : public ::testing::Test {
 protected:
  PredictedMonitorTest() : robot_(testing::LoadPanda()), scene_(testing::LoadCell()) {
    on_.predict_ssm = true;
  }
  // From the tool at (0.45, -0.35, 0.30) to (0.45, 0.15, 0.30) (m, W), past
  // a hand held still at (hand_x, -0.10, 0.30) (hand_, which the request
  // points into); the goal's joint positions in *goal.
  PlanningRequest PassTheHand(double hand_x, Eigen::VectorXd* goal) {
    const Planner plain(robot_, scene_, off_);
    const IkResult s = plain.SolveIk({0.45, -0.35, 0.30}, DownOrientation(0.0), Ready(), 1);
    const IkResult g = plain.SolveIk({0.45, 0.15, 0.30}, DownOrientation(0.0), Ready(), 1);
    EXPECT_TRUE(s.success && g.success);
    hand_.emplace(Hand(31, [hand_x](int) { return Eigen::Vector3d(hand_x, -0.10, 0.30); }));
    PlanningRequest req;
    req.start_q = s.q;
    req.goal = Goal::Joint(g.q);
    req.people = {{&*hand_, 0.1, 0.0}};
    *goal = g.q;
    return req;
  }
  collision::RobotModel robot_;
  collision::SceneParams scene_;
  PlannerParams off_, on_;
  std::optional<collision::HumanPrediction> hand_;
  const int last_ = static_cast<int>(std::lround(PlannerParams{}.ssm_horizon / PlannerParams{}.dt));
};

TEST_F(PredictedMonitorTest, RefusesAPlanTheMonitorWouldStop) {
  // A hand held still 0.22 m beside the middle of the straight path: the
  // collision bound is negligible there, but a robot passing at speed is
  // inside the protective separation (S_p = 0.17 m + 0.25 s x v_r).
  const Planner plain(robot_, scene_, off_);
  Eigen::VectorXd goal;
  const PlanningRequest req = PassTheHand(0.70, &goal);
  const collision::HumanPrediction& hand = *hand_;
  const int last = last_;
  const double retreat = 2.0 * on_.ssm.retreat_speed;

  const PlanningResult blind = plain.Plan(req);
  ASSERT_TRUE(blind.success()) << blind.reason;
  EXPECT_LT(blind.max_bound, 1.0 - off_.delta_cl);  // the bound alone is content
  EXPECT_LT(MonitorMargin(robot_, blind.positions, 0.1, hand, on_.ssm, last, retreat), 0.0);  // the monitor is not

  const Planner predicting(robot_, scene_, on_);
  const PlanningResult seen = predicting.Plan(req);
  ASSERT_TRUE(seen.success()) << seen.reason;
  EXPECT_GE(MonitorMargin(robot_, seen.positions, 0.1, hand, on_.ssm, last, retreat), on_.ssm_margin - 1e-9);
  EXPECT_GE(seen.ssm_margin, on_.ssm_margin - 1e-9);
  EXPECT_EQ(seen.positions.col(seen.positions.cols() - 1), goal);  // it still gets there
}

// A depth point's speed allowance (HumanPrediction::speed_allowance): the
// monitor adds it to the point's speed towards the robot, so the planner
// plans for the larger protective separation it asks for (passing slower or
// further away), while the sphere keeps its own radius for the bound.
TEST_F(PredictedMonitorTest, APointsSpeedAllowanceIsPredictedAsTheMonitorAddsIt) {
  Eigen::VectorXd goal;
  const PlanningRequest req = PassTheHand(0.85, &goal);
  const int last = last_;
  const double retreat = 2.0 * on_.ssm.retreat_speed, allowance = 0.6;
  const Planner predicting(robot_, scene_, on_);
  const PlanningResult plain = predicting.Plan(req);
  ASSERT_TRUE(plain.success()) << plain.reason;
  EXPECT_GE(MonitorMargin(robot_, plain.positions, 0.1, *hand_, on_.ssm, last, retreat), on_.ssm_margin - 1e-9);
  // The same plan, judged with the allowance: the monitor would stop it.
  EXPECT_LT(MonitorMargin(robot_, plain.positions, 0.1, *hand_, on_.ssm, last, retreat, false, allowance), 0.0);

  ASSERT_TRUE(hand_->set_speed_allowance(0, allowance));
  EXPECT_FALSE(hand_->set_speed_allowance(0, -1.0));
  EXPECT_FALSE(hand_->set_speed_allowance(0, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_DOUBLE_EQ(hand_->speed_allowance(0), allowance);
  const PlanningResult wide = predicting.Plan(req);
  ASSERT_TRUE(wide.success()) << wide.reason;
  EXPECT_GE(MonitorMargin(robot_, wide.positions, 0.1, *hand_, on_.ssm, last, retreat, false, allowance),
            on_.ssm_margin - 1e-9);
  EXPECT_GE(wide.ssm_margin, on_.ssm_margin - 1e-9);
  EXPECT_EQ(wide.positions.col(wide.positions.cols() - 1), goal);
  EXPECT_GT((wide.positions - plain.positions).cwiseAbs().maxCoeff(), 0.05);  // another plan, not the same one
}

TEST_F(PredictedMonitorTest, WithTheMonitorsSlowingPredictedAPlanItWouldOnlySlowDownGoesAhead) {
  // A hand held still 0.28 m beside the middle of the straight path (further
  // than in RefusesAPlanTheMonitorWouldStop): the monitor would slow the
  // free plan down there (d - S_p < 0 at its speed), not stop it. Judged by
  // the monitor's stop (ssm_predicts_slowing: the rule at min_speed_scale of
  // the plan's speed), the plan may pass closer than the rule at its own
  // speed allows, so it keeps nearer to the free path (a lower cost), and
  // the monitor still never has to stop it.
  PlannerParams slowing = on_;
  slowing.ssm_predicts_slowing = true;
  ASSERT_TRUE(slowing.ssm.speed_reduction);
  const Planner blind_planner(robot_, scene_, off_), strict(robot_, scene_, on_), predicting(robot_, scene_, slowing);
  Eigen::VectorXd goal;
  const PlanningRequest req = PassTheHand(0.76, &goal);
  const collision::HumanPrediction& hand = *hand_;
  const int last = last_;
  const double retreat = 2.0 * on_.ssm.retreat_speed;
  auto margin = [&](const PlanningResult& r) { return MonitorMargin(robot_, r.positions, 0.1, hand, on_.ssm, last, retreat); };
  auto stop_scale = [&](const PlanningResult& r) {
    return MonitorMargin(robot_, r.positions, 0.1, hand, on_.ssm, last, retreat, true);
  };

  const PlanningResult blind = blind_planner.Plan(req);
  const PlanningResult kept = strict.Plan(req);
  const PlanningResult slowed = predicting.Plan(req);
  ASSERT_TRUE(blind.success() && kept.success() && slowed.success()) << blind.reason << kept.reason << slowed.reason;
  EXPECT_LT(margin(blind), 0.0);  // the free plan: inside S_p at its speed, the monitor would stop it
  EXPECT_LT(stop_scale(blind), on_.ssm.min_speed_scale);
  // The rule at the plan's speed keeps the margin; judged by the stop, the
  // plan goes closer (below ssm_margin at its own speed) and costs less ...
  EXPECT_GE(margin(kept), on_.ssm_margin - 1e-9);
  EXPECT_LT(margin(slowed), on_.ssm_margin);
  EXPECT_LT(slowed.cost, kept.cost);
  // ... and the monitor would at most slow it down, never stop it.
  EXPECT_GE(stop_scale(slowed), on_.ssm.min_speed_scale);
  EXPECT_GE(slowed.ssm_margin, on_.ssm_margin - 1e-9);  // the planner's own account, at min_speed_scale
  EXPECT_EQ(slowed.positions.col(slowed.positions.cols() - 1), goal);
  // Without the monitor's speed reduction there is no slowing to predict:
  // the rule at the plan's own speed, as without the option.
  PlannerParams no_reduction = slowing;
  no_reduction.ssm.speed_reduction = false;
  const PlanningResult r = Planner(robot_, scene_, no_reduction).Plan(req);
  ASSERT_TRUE(r.success()) << r.reason;
  EXPECT_GE(margin(r), on_.ssm_margin - 1e-9);
}

TEST_F(PredictedMonitorTest, ARobotInThePersonsWayGetsOutOfIt) {
  // The robot rests at its goal; the hand is predicted to come straight at
  // the tool at 0.25 m/s, from 0.5 m away to 0.25 m in 1 s. Holding still
  // there is what the monitor would stop (and where the contact would be);
  // the plan withdraws instead, within the monitor's rule.
  const Planner predicting(robot_, scene_, on_);
  const IkResult at = predicting.SolveIk({0.50, 0.0, 0.30}, DownOrientation(0.0), Ready(), 1);
  ASSERT_TRUE(at.success);
  collision::RobotData d(robot_);
  collision::CalcForwardKinematics(robot_, at.q, &d);
  const int tool = static_cast<int>(robot_.spheres.size()) - 1;
  const Eigen::Vector3d tool_W = d.p_WS.col(tool);
  const collision::HumanPrediction hand =
      Hand(16, [&](int k) { return Eigen::Vector3d(tool_W + Eigen::Vector3d(0.5 - 0.025 * std::min(k, 10), 0, 0)); });
  PlanningRequest req;
  req.start_q = at.q;
  req.goal = Goal::Joint(at.q);
  req.people = {{&hand, 0.1, 0.0}};
  const int last = static_cast<int>(std::lround(on_.ssm_horizon / on_.dt));

  const Eigen::MatrixXd hold = at.q.replicate(1, last + 2);
  EXPECT_LT(MonitorMargin(robot_, hold, 0.1, hand, on_.ssm, last, 2.0 * on_.ssm.retreat_speed), 0.0);

  const PlanningResult r = predicting.Plan(req);
  ASSERT_TRUE(r.success()) << r.reason;
  EXPECT_GE(MonitorMargin(robot_, r.positions, 0.1, hand, on_.ssm, last, 2.0 * on_.ssm.retreat_speed),
            on_.ssm_margin - 1e-9);
  // It moved the tool away from where the hand is going.
  collision::CalcForwardKinematics(robot_, r.positions.col(last), &d);
  const Eigen::Vector3d hand_end = hand.sphere(0, last, 0).mean;
  EXPECT_GT((d.p_WS.col(tool) - hand_end).norm(), (tool_W - hand_end).norm() + 0.05);
}

TEST_F(PredictedMonitorTest, AnUnlikelyActionDoesNotBlockTheGoal) {
  // The same approach, predicted with 30 % (below ssm_stop_probability
  // 0.5): the monitor would more likely than not let the robot stand, so
  // it stays at its goal instead of withdrawing.
  const Planner predicting(robot_, scene_, on_);
  const IkResult at = predicting.SolveIk({0.50, 0.0, 0.30}, DownOrientation(0.0), Ready(), 1);
  ASSERT_TRUE(at.success);
  collision::RobotData d(robot_);
  collision::CalcForwardKinematics(robot_, at.q, &d);
  const Eigen::Vector3d tool_W = d.p_WS.col(static_cast<int>(robot_.spheres.size()) - 1);
  const collision::HumanPrediction hand = Hand(
      16, [&](int k) { return Eigen::Vector3d(tool_W + Eigen::Vector3d(0.5 - 0.025 * std::min(k, 10), 0, 0)); }, 0.3);
  PlanningRequest req;
  req.start_q = at.q;
  req.goal = Goal::Joint(at.q);
  req.people = {{&hand, 0.1, 0.0}};
  const PlanningResult r = predicting.Plan(req);
  ASSERT_TRUE(r.success()) << r.reason;
  const int last = static_cast<int>(std::lround(on_.ssm_horizon / on_.dt));
  EXPECT_LT((r.positions.col(last) - at.q).cwiseAbs().maxCoeff(), 0.01);
}

TEST(PredictedMonitorParams, BadValuesAreRefusedByName) {
  PlannerParams p;
  p.ssm_margin = -0.01;
  EXPECT_NE(p.Validate().find("ssm_margin"), std::string::npos);
  p = PlannerParams{};
  p.ssm_activation = 0.01;  // below ssm_margin 0.03
  EXPECT_NE(p.Validate().find("ssm_activation"), std::string::npos);
  p = PlannerParams{};
  p.ssm_stop_probability = 0.0;
  EXPECT_NE(p.Validate().find("ssm_stop_probability"), std::string::npos);
  p = PlannerParams{};
  p.ssm.stopping_speed = 0.0;
  EXPECT_NE(p.Validate().find("iso_ts_15066"), std::string::npos);
}

}  // namespace
}  // namespace iplan::planning
