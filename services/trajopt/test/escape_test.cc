// Escaping (core/escape.h): when no safe plan exists and standing still is
// what the bound forbids, the robot takes the plan that gets it out of the
// person's predicted way, as the monitor's bound retreat lets it.
#include "services/trajopt/core/escape.h"

#include <algorithm>
#include <limits>
#include <memory>

#include <gtest/gtest.h>

#include "replanner_fixture.h"

namespace iplan::trajopt {
namespace {

// A person whose right hand sweeps along +y through the point `through`
// (m, world) at 1.2 m/s, from 0.9 m before it, the body following; 15
// steps of 0.1 s from t0, the hand at each step where it will then be.
collision::JointMixture Sweep(const collision::HumanBodyModel& body, int64_t t0, double elapsed,
                              const Eigen::Vector3d& through) {
  const Eigen::Vector3d torso = through + Eigen::Vector3d(0.45, 0.0, 0.1);
  const Eigen::Vector3d shoulder_r = torso + Eigen::Vector3d(0, 0.18, 0.25);
  return ReplannerTest::Mixture(body, t0, 15, [&](int k) {
    const Eigen::Vector3d hand = through + Eigen::Vector3d(0, -0.9 + 1.2 * (elapsed + 0.1 * (k + 1)), 0);
    return ReplannerTest::Body(torso, hand, 0.5 * (hand + shoulder_r));
  });
}

TEST_F(ReplannerTest, StandingInTheSweepIsWhatTheBoundForbidsAndAnEscapeLowersIt) {
  const std::unique_ptr<planning::Planner> planner = PredictingPlanner();
  const Eigen::Vector3d tool = ToolAtReady(planner->robot());
  const collision::JointMixture sweep = Sweep(body_, 0, 0.0, tool);
  cell::TimedPrediction p;
  ASSERT_EQ(cell::TimedPrediction::Build(body_, sweep, &p), std::nullopt);
  planning::PlanningRequest req;
  req.start_q = Ready();
  req.goal = planning::Goal::Joint(Ready());
  req.people.push_back({&p.spheres(), p.time_step(), p.StartRelativeTo(0)});
  const double hold = HoldBound(*planner, req, Ready(), 1.0);
  EXPECT_GE(hold, 0.05) << "the hand passes through the tool within the horizon";
  // Far from the sweep (the whole person 2 m further), standing still is fine.
  collision::JointMixture far = sweep;
  for (auto& mu : far.means[0]) mu += Eigen::Vector3d(2.0, 0, 0);
  cell::TimedPrediction q;
  ASSERT_EQ(cell::TimedPrediction::Build(body_, far, &q), std::nullopt);
  planning::PlanningRequest clear = req;
  clear.people = {{&q.spheres(), q.time_step(), q.StartRelativeTo(0)}};
  EXPECT_LT(HoldBound(*planner, clear, Ready(), 1.0), 1e-3);
  // Planning to stay fails; an escape lowers the bound by at least the gain.
  const planning::PlanningResult stay = planner->Plan(req);
  ASSERT_FALSE(stay.success()) << "staying put is unsafe";
  const std::optional<planning::PlanningResult> escape = FindEscape(*planner, req, stay, Ready(), hold, EscapeParams{});
  ASSERT_TRUE(escape.has_value());
  EXPECT_LE(HorizonBound(escape->bounds, planner->params().dt, 1.0), hold - 0.05);
  EXPECT_EQ(planning::CheckLimits(planner->robot(), escape->positions, planner->params().dt, Eigen::VectorXd()), "");
  // Off (gain 0): no escape.
  EXPECT_FALSE(FindEscape(*planner, req, stay, Ready(), hold, EscapeParams{1.0, 0.0}).has_value());
  // Standing still already fine: nothing lowers it by the gain.
  EXPECT_FALSE(FindEscape(*planner, clear, planner->Plan(clear), Ready(), 0.0, EscapeParams{}).has_value());
}

// The forearm's spheres (the body model's: radius 0.06 m at 1/4 and at the
// hand) at `elapsed` s of the sweep: their smallest surface distance (m) to
// any sphere of the robot at q.
double ForearmClearance(const collision::RobotModel& robot, const Eigen::VectorXd& q, const Eigen::Vector3d& through,
                        double elapsed) {
  const Eigen::Vector3d hand = through + Eigen::Vector3d(0, -0.9 + 1.2 * elapsed, 0);
  const Eigen::Vector3d shoulder = through + Eigen::Vector3d(0.45, 0.18, 0.35);
  const Eigen::Vector3d elbow = 0.5 * (hand + shoulder);
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, q, &d);
  double clearance = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& c : {Eigen::Vector3d(elbow + 0.25 * (hand - elbow)), hand}) {
    for (int s = 0; s < d.p_WS.cols(); ++s) {
      const double r = robot.spheres[static_cast<std::size_t>(s)].radius;
      clearance = std::min(clearance, (d.p_WS.col(s) - c).norm() - r - 0.06);
    }
  }
  return clearance;
}

// The replanner, idle at the ready pose, with the hand about to sweep
// through its tool: it gets out of the way (the ideal robot follows), where
// standing still the forearm would pass through the arm.
TEST_F(ReplannerTest, AnIdleRobotInTheSweepOfAHandEscapesIt) {
  const std::unique_ptr<planning::Planner> planner = PredictingPlanner();
  Replanner replanner(*planner, body_, ReplannerParams{});
  const collision::RobotModel& robot = planner->robot();
  const Eigen::Vector3d tool = ToolAtReady(robot);
  const int64_t t0 = 100 * kSec;
  int64_t t = t0;
  Eigen::VectorXd q = Ready();
  std::vector<std::string> statuses;
  double escaping = std::numeric_limits<double>::infinity(), standing = escaping;
  for (int k = 0; k < 15; ++k) {
    const double elapsed = (t - t0) * 1e-9;
    const std::vector<double> qv(q.data(), q.data() + q.size());
    ASSERT_EQ(replanner.UpdateRobotState(t, replanner.joint_names(), qv, std::vector<double>(7, 0.0)), std::nullopt);
    ASSERT_EQ(replanner.UpdatePrediction(Sweep(body_, t, elapsed, tool)), std::nullopt);
    const CycleResult c = replanner.Cycle(t);
    ASSERT_TRUE(c.publish) << c.status;
    statuses.push_back(c.status);
    for (int i = 1; i <= 10; ++i) {  // every 0.01 s of the step
      const int64_t ti = t + i * kSec / 100;
      escaping = std::min(escaping, ForearmClearance(robot, At(c, ti), tool, (ti - t0) * 1e-9));
      standing = std::min(standing, ForearmClearance(robot, Ready(), tool, (ti - t0) * 1e-9));
    }
    t += kSec / 10;
    q = At(c, t);
  }
  EXPECT_NE(std::find_if(statuses.begin(), statuses.end(),
                         [](const std::string& s) { return s.find("escaping") != std::string::npos; }),
            statuses.end())
      << statuses.front();
  EXPECT_LT(standing, -0.05) << "standing still, the forearm sweeps through the arm";
  EXPECT_GT(escaping, 0.0) << "escaping, it does not touch it";
}

}  // namespace
}  // namespace iplan::trajopt
