#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "iplan/collision/human_model.h"
#include "iplan/collision/static_scene.h"
#include "iplan/planning/planner.h"
#include "test_util.h"

namespace iplan::planning {
namespace {

using testing::DownOrientation;
using testing::Ready;

class PlannerTest : public ::testing::Test {
 protected:
  PlannerTest()
      : robot_(testing::LoadPanda()),
        scene_params_(testing::LoadCell()),
        planner_(robot_, scene_params_, PlannerParams{}),
        scene_(scene_params_),
        body_(collision::HumanBodyParams::DefaultUpperBody()) {}

  // The sweep most cases plan (testing::AcrossTheTable).
  PlanningRequest AcrossTheTable() const {
    const std::optional<PlanningRequest> req = testing::AcrossTheTable(planner_);
    EXPECT_TRUE(req.has_value()) << "no IK solution for the sweep across the table";
    return req.value_or(PlanningRequest{});
  }

  // From Ready to a pose on the shelf while a person's hand reaches across
  // its way (the prediction is the fixture's shelf_reach_).
  PlanningRequest ToTheShelfPastAReach() {
    shelf_reach_.emplace(testing::MakeReachingPrediction(body_, {{0.5, -0.2, 0.4}, {0.6, 0.2, 0.3}}, 15));
    PlanningRequest req;
    req.start_q = Ready();
    req.goal = Goal::Pose({0.35, -0.40, 0.65}, DownOrientation(0.3));
    req.people = {{&*shelf_reach_, 0.1, 0.0}};
    return req;
  }

  // Independent check with FCL of the static clearance at 10x the waypoint
  // resolution (linear interpolation), allowed pairs excluded.
  double FclClearance(const Eigen::MatrixXd& Q) const {
    collision::RobotData d(robot_);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < Q.cols(); ++i) {
      for (int s = 0; s < (i + 1 < Q.cols() ? 10 : 1); ++s) {
        const Eigen::VectorXd q =
            i + 1 < Q.cols() ? Eigen::VectorXd(Q.col(i) + 0.1 * s * (Q.col(i + 1) - Q.col(i)))
                             : Eigen::VectorXd(Q.col(i));
        collision::CalcForwardKinematics(robot_, q, &d);
        for (int o = 0; o < scene_.num_objects(); ++o)
          for (int sp : planner_.CheckedSpheres(o))
            best = std::min(best, scene_.CalcSignedDistance(o, d.p_WS.col(sp), robot_.spheres[sp].radius));
      }
    }
    return best;
  }

  void ExpectValid(const PlanningResult& r, const Eigen::VectorXd& start) const {
    ASSERT_TRUE(r.success()) << r.reason;
    ASSERT_EQ(r.positions.rows(), 7);
    EXPECT_EQ(r.positions.col(0), start);  // start state kept exactly
    EXPECT_EQ(CheckLimits(robot_, r.positions, r.dt, Eigen::VectorXd()), "");
    EXPECT_GE(FclClearance(r.positions), -1e-9);
    EXPECT_EQ(r.positions.col(r.positions.cols() - 1), r.goal_q);
  }

  collision::RobotModel robot_;
  collision::SceneParams scene_params_;
  Planner planner_;
  collision::StaticScene scene_;
  collision::HumanBodyModel body_;
  std::optional<collision::HumanPrediction> shelf_reach_;
};

TEST_F(PlannerTest, JointGoalIsValid) {
  PlanningRequest req;
  req.start_q = Ready();
  Eigen::VectorXd goal(7);
  goal << 1.2, 0.3, 0.0, -1.7, 0.0, 2.0, 0.8;
  req.goal = Goal::Joint(goal);
  const PlanningResult r = planner_.Plan(req);
  ExpectValid(r, req.start_q);
  EXPECT_EQ(r.positions.cols(), 31);
  EXPECT_EQ(r.num_waits, 0);
  EXPECT_DOUBLE_EQ(r.delay, 0.0);
}

TEST_F(PlannerTest, PoseGoalsBetweenTableTopPosesAreValid) {
  const auto poses = testing::TableTopPoses();
  int successes = 0;
  for (std::size_t a = 0; a < poses.size(); a += 3) {
    const IkResult start_ik = planner_.SolveIk(poses[a].p, DownOrientation(0.0), Ready(), 1);
    ASSERT_TRUE(start_ik.success) << poses[a].name;
    for (std::size_t b = 0; b < poses.size(); b += 2) {
      if (a == b) continue;
      PlanningRequest req;
      req.start_q = start_ik.q;
      req.goal = Goal::Pose(poses[b].p, DownOrientation(0.0));
      const PlanningResult r = planner_.Plan(req);
      SCOPED_TRACE(std::string(poses[a].name) + " -> " + poses[b].name);
      ExpectValid(r, req.start_q);
      successes += r.success();
      // The goal configuration reaches the pose.
      collision::RobotData d(robot_);
      collision::CalcForwardKinematics(robot_, r.goal_q, &d);
      EXPECT_LT((d.X_WL[robot_.FindLink("panda_link8")].translation() - poses[b].p).norm(), 1e-3);
    }
  }
  EXPECT_GT(successes, 0);
}

TEST_F(PlannerTest, PersonAcrossThePathIsAvoidedOrWaitedFor) {
  // Start on the right of the table, goal on the left; the person's hand
  // reaches to the middle of the straight-line path and stays there.
  const collision::HumanPrediction pred =
      testing::MakeReachingPrediction(body_, {{0.50, -0.02, 0.30}, {0.55, 0.0, 0.25}}, 15, 0.02, 0.05);
  PlanningRequest req = AcrossTheTable();
  // Without the person, the straight path crosses the hand's region.
  const PlanningResult free_r = planner_.Plan(req);
  ASSERT_TRUE(free_r.success());
  req.people = {{&pred, 0.1, 0.0}};
  const PlanningResult r = planner_.Plan(req);
  const double thr = 1.0 - planner_.params().delta_cl;
  if (r.success()) {
    ExpectValid(r, req.start_q);
    ASSERT_EQ(static_cast<int>(r.bounds.size()), r.positions.cols());
    for (std::size_t i = 0; i < r.bounds.size(); ++i) EXPECT_LT(r.bounds[i], thr) << "waypoint " << i;
    EXPECT_LT(r.max_bound, thr);
    EXPECT_NEAR(r.delay, r.num_waits * planner_.params().wait_duration, 1e-12);
    EXPECT_EQ(r.positions.cols(), 31 + r.num_waits * 5);
  } else {
    EXPECT_EQ(r.status, PlanStatus::kNoSafeTrajectory) << r.reason;
    EXPECT_EQ(r.num_waits, planner_.params().max_waits);
    EXPECT_GT(r.delay, 0.0);
  }
}

// One person's exact bound of every waypoint of Q (prediction step s at
// s * 0.1 s, the nearest step per waypoint), computed here independently.
std::vector<double> PersonBounds(const collision::RobotModel& robot, const collision::HumanPrediction& pred,
                                 const Eigen::MatrixXd& Q, double dt) {
  collision::RobotSpheresTrajectory rs;
  for (const auto& sp : robot.spheres) {
    rs.radii.push_back(sp.radius);
    rs.links.push_back(sp.link);
  }
  const int S = static_cast<int>(robot.spheres.size());
  rs.centres.resize(3, Q.cols() * S);
  collision::RobotData d(robot);
  for (int i = 0; i < Q.cols(); ++i) {
    collision::CalcForwardKinematics(robot, Q.col(i), &d);
    rs.centres.middleCols(static_cast<Eigen::Index>(i) * S, S) = d.p_WS;
    rs.steps.push_back(std::clamp(static_cast<int>(std::lround(i * dt / 0.1)), 0, pred.num_steps() - 1));
  }
  collision::TrajectoryBoundWorkspace ws(S, pred.num_spheres());
  std::vector<collision::WaypointBound> wb;
  collision::EvaluateTrajectoryBound(pred, rs, collision::TrajectoryBoundParams{}, &ws, &wb);
  std::vector<double> out;
  for (const auto& b : wb) out.push_back(b.bound);
  return out;
}

TEST_F(PlannerTest, TwoPeopleAreBoundedByTheSumOfTheirBounds) {
  // The person of PersonAcrossThePath, and a second one reaching from the
  // other side of the path (torso 0.3 m further along y).
  const collision::HumanPrediction a =
      testing::MakeReachingPrediction(body_, {{0.50, -0.02, 0.30}, {0.55, 0.0, 0.25}}, 15, 0.02, 0.05);
  const collision::HumanPrediction b = testing::MakeReachingPrediction(
      body_, {{0.52, -0.15, 0.35}}, 15, 0.02, 0.05, Eigen::Vector3d(0.05, -0.3, 0.0));
  PlanningRequest req = AcrossTheTable();
  req.people = {{&a, 0.1, 0.0}, {&b, 0.1, 0.0}};
  const PlanningResult r = planner_.Plan(req);
  ASSERT_EQ(static_cast<int>(r.bounds.size()), r.positions.cols());
  const std::vector<double> pa = PersonBounds(robot_, a, r.positions, r.dt);
  const std::vector<double> pb = PersonBounds(robot_, b, r.positions, r.dt);
  int both = 0;
  for (std::size_t i = 0; i < r.bounds.size(); ++i) {
    EXPECT_NEAR(r.bounds[i], std::min(1.0, pa[i] + pb[i]), 1e-12) << "waypoint " << i;
    both += pa[i] > 1e-4 && pb[i] > 1e-4;
  }
  EXPECT_GT(both, 0) << "both persons near the path somewhere";
  const double thr = 1.0 - planner_.params().delta_cl;
  if (r.success()) {
    ExpectValid(r, req.start_q);
    for (int i = r.num_frozen; i < r.positions.cols(); ++i) EXPECT_LT(pa[i] + pb[i], thr) << "waypoint " << i;
  } else {
    EXPECT_EQ(r.status, PlanStatus::kNoSafeTrajectory) << r.reason;
  }
}

TEST_F(PlannerTest, APersonFarAwayChangesNothing) {
  const collision::HumanPrediction near =
      testing::MakeReachingPrediction(body_, {{0.50, -0.02, 0.30}, {0.55, 0.0, 0.25}}, 15, 0.02, 0.05);
  const collision::HumanPrediction far = testing::MakeReachingPrediction(
      body_, {{3.0, 0.0, 0.3}}, 15, 0.02, 0.05, Eigen::Vector3d(3.0, 0.0, 0.0));
  PlanningRequest req = AcrossTheTable();
  req.people = {{&near, 0.1, 0.0}};
  const PlanningResult one = planner_.Plan(req);
  req.people = {{&far, 0.1, 0.0}, {&near, 0.1, 0.0}};
  const PlanningResult two = planner_.Plan(req);
  EXPECT_EQ(two.status, one.status);
  ASSERT_EQ(two.positions.cols(), one.positions.cols());
  EXPECT_EQ(two.positions, one.positions);  // bit-identical: the far person's terms are ~1e-100
  EXPECT_EQ(two.num_waits, one.num_waits);
  EXPECT_NEAR(two.max_bound, one.max_bound, 1e-15);
  EXPECT_EQ(two.human_separation, one.human_separation);  // the nearest person's
}

TEST_F(PlannerTest, RefusesAPersonWithoutAPrediction) {
  PlanningRequest req;
  req.start_q = Ready();
  req.goal = Goal::Joint(Ready());
  req.people = {{nullptr, 0.1, 0.0}};
  EXPECT_THROW(planner_.Plan(req), std::invalid_argument);
  const collision::HumanPrediction p = testing::MakeReachingPrediction(body_, {{0.5, 0.0, 0.3}}, 15);
  req.people = {{&p, 0.1, 0.0}, {&p, 0.0, 0.0}};
  try {
    planner_.Plan(req);
    ADD_FAILURE() << "dt 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("person 1: time_step must be > 0 s"), std::string::npos) << e.what();
  }
}

TEST_F(PlannerTest, PersonStandingOnTheGoalForcesWaitsAndAReportedDelay) {
  // The hand rests on the goal pose for the whole prediction.
  const collision::HumanPrediction pred =
      testing::MakeReachingPrediction(body_, {{0.45, 0.15, 0.30}}, 15, 0.03, 0.03);
  PlanningRequest req = AcrossTheTable();
  req.people = {{&pred, 0.1, 0.0}};
  const PlanningResult r = planner_.Plan(req);
  EXPECT_FALSE(r.success());
  EXPECT_EQ(r.status, PlanStatus::kNoSafeTrajectory) << r.reason;
  EXPECT_EQ(r.num_waits, planner_.params().max_waits);
  EXPECT_NEAR(r.delay, r.num_waits * 0.5, 1e-12);
  EXPECT_GE(r.max_bound, 1.0 - planner_.params().delta_cl);
  // A request may forbid waits (an escape must move now): one attempt.
  req.max_waits = 0;
  const PlanningResult now = planner_.Plan(req);
  EXPECT_EQ(now.status, PlanStatus::kNoSafeTrajectory) << now.reason;
  EXPECT_EQ(now.num_waits, 0);
  EXPECT_EQ(now.delay, 0.0);
  EXPECT_EQ(now.positions.cols(), r.positions.cols() - r.num_waits * 5);
}

TEST_F(PlannerTest, SeparationKeepOutHoldsPlansAwayFromThePredictedPerson) {
  // A hand held still 0.30 m beside the middle of the straight path: far
  // enough for a negligible collision bound, too close for the ISO/TS 15066
  // protective separation the keep-out stands for.
  collision::HumanPrediction hand(1, 31, {0.05});
  hand.set_action_probability(0, 1.0);
  for (int k = 0; k < 31; ++k)
    ASSERT_TRUE(hand.SetSphere(0, k, 0, {0.75, -0.10, 0.30}, 0.0004 * Eigen::Matrix3d::Identity()));
  hand.UpdateSummaries();
  PlanningRequest req = AcrossTheTable();
  req.people = {{&hand, 0.1, 0.0}};
  const PlanningResult off = planner_.Plan(req);
  ExpectValid(off, req.start_q);
  EXPECT_LT(off.max_bound, 1.0 - planner_.params().delta_cl);
  EXPECT_LT(off.human_separation, 0.25);  // the free path passes close by

  PlannerParams p;
  p.human_separation = 0.30;
  const Planner keep_out(robot_, scene_params_, p);
  const PlanningResult on = keep_out.Plan(req);
  ExpectValid(on, req.start_q);
  // Soft: the plan goes round at about the keep-out distance.
  EXPECT_GT(on.human_separation, off.human_separation + 0.03);
  EXPECT_GT(on.human_separation, 0.25);
  // An unlikely action does not shape plans (below 30 %).
  hand.set_action_probability(0, 0.2);
  hand.UpdateSummaries();
  const PlanningResult unlikely = keep_out.Plan(req);
  ExpectValid(unlikely, req.start_q);
  EXPECT_EQ(unlikely.positions, planner_.Plan(req).positions);
  EXPECT_EQ(unlikely.human_separation, std::numeric_limits<double>::infinity());  // no action counted
}

TEST_F(PlannerTest, SameSeedIsBitIdenticalForAnyThreadCount) {
  const PlanningRequest req = ToTheShelfPastAReach();
  const PlanningResult a = planner_.Plan(req, 6, 1, 42);
  const PlanningResult b = planner_.Plan(req, 6, 3, 42);
  const PlanningResult c = planner_.Plan(req, 6, 6, 42);
  ASSERT_EQ(a.positions.cols(), b.positions.cols());
  ASSERT_EQ(a.positions.cols(), c.positions.cols());
  EXPECT_TRUE(a.positions == b.positions);
  EXPECT_TRUE(a.positions == c.positions);
  EXPECT_EQ(a.cost, b.cost);
  EXPECT_EQ(a.winning_optimizer, c.winning_optimizer);
  if (a.success()) ExpectValid(a, req.start_q);
  if (b.success()) ExpectValid(b, req.start_q);
  // A different seed perturbs optimisers 1..N-1 differently.
  const PlanningResult d = planner_.Plan(req, 6, 2, 43);
  if (d.winning_optimizer != 0 || a.winning_optimizer != 0) {
    EXPECT_FALSE(a.positions == d.positions);
  }
}

TEST_F(PlannerTest, EarlyStopIsBitIdenticalForAnyThreadCountAndValid) {
  // Rounds of 2 iterations: the optimisers stop at the first round with a
  // feasible and safe one, decided on their states only.
  PlannerParams p;
  p.early_stop_interval = 2;
  const Planner planner(robot_, scene_params_, p);
  // The person reaches on their own side of the table.
  const collision::HumanPrediction pred =
      testing::MakeReachingPrediction(body_, {{0.80, 0.0, 0.25}, {0.85, -0.2, 0.2}}, 15);
  PlanningRequest req = AcrossTheTable();
  req.people = {{&pred, 0.1, 0.0}};
  const PlanningResult a = planner.Plan(req, 6, 1, 42);
  ASSERT_TRUE(a.success()) << a.reason;
  ExpectValid(a, req.start_q);
  for (double b : a.bounds) EXPECT_LT(b, 1.0 - p.delta_cl);
  for (int threads : {2, 3, 6}) {
    const PlanningResult b = planner.Plan(req, 6, threads, 42);
    EXPECT_TRUE(a.positions == b.positions) << threads << " threads";
    EXPECT_EQ(a.cost, b.cost);
    EXPECT_EQ(a.winning_optimizer, b.winning_optimizer);
    EXPECT_EQ(a.num_feasible, b.num_feasible);
    EXPECT_EQ(a.bounds, b.bounds);
  }
}

TEST_F(PlannerTest, EarlyStopChangesNothingWhenNoOptimiserIsEverSafe) {
  // The prediction blocks the shelf goal: every attempt fails, so no round
  // ends early and the result equals the run without early stop.
  PlannerParams p;
  p.early_stop_interval = 2;
  const Planner planner(robot_, scene_params_, p);
  const PlanningRequest req = ToTheShelfPastAReach();
  const PlanningResult a = planner.Plan(req, 4, 2, 42);
  const PlanningResult b = planner_.Plan(req, 4, 2, 42);
  ASSERT_FALSE(a.success());
  EXPECT_EQ(a.status, PlanStatus::kNoSafeTrajectory);
  EXPECT_TRUE(a.positions == b.positions);
  EXPECT_EQ(a.cost, b.cost);
  EXPECT_EQ(a.num_waits, b.num_waits);
}

TEST_F(PlannerTest, AnExhaustedBudgetStopsTheOptimisersAndInsertsNoWait) {
  // The person standing on the goal: without a budget the planner inserts
  // waits (PersonStandingOnTheGoalForcesWaitsAndAReportedDelay).
  const collision::HumanPrediction pred =
      testing::MakeReachingPrediction(body_, {{0.45, 0.15, 0.30}}, 15, 0.02, 0.02);
  PlanningRequest req = AcrossTheTable();
  req.people = {{&pred, 0.1, 0.0}};
  const PlanningResult unlimited = planner_.Plan(req);
  EXPECT_FALSE(unlimited.budget_exhausted);
  ASSERT_GT(unlimited.num_waits, 0) << unlimited.reason;
  // A budget no optimiser can meet: they stop at once, no wait is inserted,
  // and the outcome is what the first attempt's initial trajectories give.
  req.time_budget = 1e-9;
  const PlanningResult cut = planner_.Plan(req);
  EXPECT_TRUE(cut.budget_exhausted);
  EXPECT_EQ(cut.num_waits, 0);
  EXPECT_FALSE(cut.success()) << "the initial straight line runs through the person";
  EXPECT_EQ(cut.status, PlanStatus::kNoSafeTrajectory) << cut.reason;
  // A budget that is never reached changes nothing, bit for bit.
  req.time_budget = 1e6;
  const PlanningResult generous = planner_.Plan(req);
  EXPECT_FALSE(generous.budget_exhausted);
  EXPECT_EQ(generous.status, unlimited.status);
  EXPECT_EQ(generous.num_waits, unlimited.num_waits);
  EXPECT_TRUE(generous.positions == unlimited.positions);
  EXPECT_EQ(generous.cost, unlimited.cost);
  req.time_budget = -1;
  EXPECT_THROW(planner_.Plan(req), std::invalid_argument);
}

TEST_F(PlannerTest, OneAndManyOptimisersAreValid) {
  PlanningRequest req;
  req.start_q = Ready();
  req.goal = Goal::Pose({0.55, 0.45, 0.48}, DownOrientation(0.0));
  ExpectValid(planner_.Plan(req, 1, 1, 5), req.start_q);
  ExpectValid(planner_.Plan(req, 8, 2, 5), req.start_q);
}

TEST_F(PlannerTest, WarmStartKeepsTheFrozenPrefixAndStartVelocity) {
  PlanningRequest req;
  req.start_q = Ready();
  Eigen::VectorXd goal(7);
  goal << 0.8, 0.2, 0.0, -1.8, 0.0, 2.0, 0.8;
  req.goal = Goal::Joint(goal);
  const PlanningResult first = planner_.Plan(req);
  ASSERT_TRUE(first.success());
  // Replanning 0.1 s later: the robot is at waypoint 1, moving.
  PlanningRequest next;
  next.warm_start = Planner::ShiftTrajectory(first.positions, first.dt, 0.1);
  next.start_q = next.warm_start.col(0);
  next.start_qdot = (first.positions.col(1) - first.positions.col(0)) / first.dt;
  next.num_frozen = 3;
  next.goal = req.goal;
  const PlanningResult r = planner_.Plan(next);
  ASSERT_TRUE(r.success()) << r.reason;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(r.positions.col(i), first.positions.col(i + 1));
  EXPECT_EQ(CheckLimits(robot_, r.positions, r.dt, next.start_qdot), "");
  EXPECT_GE(FclClearance(r.positions), -1e-9);
}

TEST_F(PlannerTest, MotionLongerThanTheHorizonAllowsGetsTheTimeItNeeds) {
  // 2.8 rad of joint 1 (limit 2.175 rad/s) in a 1.5 s horizon: at least
  // 1.5 x 2.8 / 2.175 = 1.93 s are needed, so the plan is stretched (up to
  // twice the horizon) instead of breaking the velocity limit.
  PlannerParams params;
  params.horizon = 1.5;
  const Planner short_horizon(robot_, scene_params_, params);
  PlanningRequest req;
  req.start_q = Ready();
  req.start_q[0] = -1.4;
  Eigen::VectorXd goal = req.start_q;
  goal[0] = 1.4;
  req.goal = Goal::Joint(goal);
  const PlanningResult r = short_horizon.Plan(req);
  ExpectValid(r, req.start_q);
  EXPECT_EQ(r.positions.cols() - 1, static_cast<int>(std::ceil(1.5 * 2.8 / 2.175 / r.dt)));
  // A short motion keeps the horizon.
  req.goal = Goal::Joint(Ready());
  req.start_q = Ready();
  req.start_q[0] = 0.3;
  const PlanningResult s = short_horizon.Plan(req);
  ASSERT_TRUE(s.success()) << s.reason;
  EXPECT_EQ(s.positions.cols(), 16);

  // Replanning from a warm start that is too short for the rest of the
  // motion: the frozen prefix is kept and the rest stretched.
  PlanningRequest next;
  next.start_q = Ready();
  next.start_q[0] = -1.4;
  next.warm_start = next.start_q.replicate(1, 4);
  next.num_frozen = 3;
  next.goal = Goal::Joint(goal);
  const PlanningResult w = short_horizon.Plan(next);
  ExpectValid(w, next.start_q);
  EXPECT_GT(w.positions.cols(), 16);
}

TEST_F(PlannerTest, UnreachablePoseIsReportedAsIkFailure) {
  PlanningRequest req;
  req.start_q = Ready();
  req.goal = Goal::Pose({1.5, 0.0, 0.4}, DownOrientation(0.0));
  const PlanningResult r = planner_.Plan(req);
  EXPECT_FALSE(r.success());
  EXPECT_EQ(r.status, PlanStatus::kIkFailed);
  EXPECT_NE(r.reason.find("no IK solution"), std::string::npos);
}

TEST_F(PlannerTest, BadInputsThrowWithTheValues) {
  auto expect_throw = [&](const PlanningRequest& req, const std::string& text) {
    try {
      planner_.Plan(req);
      ADD_FAILURE() << "no exception for " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  PlanningRequest req;
  req.start_q = Eigen::VectorXd::Zero(6);
  req.goal = Goal::Joint(Ready());
  expect_throw(req, "start has 6 joint values, the robot has 7");
  req.start_q = Ready();
  Eigen::VectorXd bad = Ready();
  bad[3] = 0.5;  // joint 4 upper limit is -0.0698
  req.goal = Goal::Joint(bad);
  expect_throw(req, "goal joint 3 = 0.5");
  bad = Ready();
  bad[2] = std::nan("");
  req.goal = Goal::Joint(bad);
  expect_throw(req, "goal is not finite");
  req.goal = Goal::Joint(Ready());
  req.start_q[0] = std::numeric_limits<double>::quiet_NaN();
  expect_throw(req, "start is not finite");
  req.start_q = Ready();
  req.goal = Goal::Pose({0.5, 0.0, std::nan("")}, DownOrientation(0.0));
  expect_throw(req, "goal pose must be finite");
  req.goal = Goal::Joint(Ready());
  req.num_frozen = 2;
  expect_throw(req, "num_frozen = 2 needs a warm_start");
}

TEST(PlannerConstruction, AdaptLinksToRobotGivesAnotherArmItsOwnLinks) {
  const PlannerParams p;
  // The Panda has the links the defaults name: nothing changes.
  const PlannerParams panda = AdaptLinksToRobot(p, testing::LoadPanda());
  EXPECT_EQ(panda.end_effector_link, p.end_effector_link);
  EXPECT_EQ(panda.end_effector_offset, p.end_effector_offset);
  EXPECT_EQ(panda.allowed_collisions, p.allowed_collisions);
  // The UR5e: its tool0, its base and shoulder on the table; it plans.
  collision::RobotModel ur = collision::LoadRobotModel(std::string(IPLAN_SHARED_DIR) + "/robots/ur5e/ur5e.urdf");
  const PlannerParams q = AdaptLinksToRobot(p, ur);
  EXPECT_EQ(q.end_effector_link, "tool0");
  EXPECT_EQ(q.end_effector_offset, (std::array<double, 3>{0.0, 0.0, 0.0}));
  const std::vector<std::pair<std::string, std::string>> base = {{"base_link_inertia", "table"},
                                                                   {"shoulder_link", "table"}};
  EXPECT_EQ(q.allowed_collisions, base);
  EXPECT_NO_THROW(Planner(ur, testing::LoadCell(), q));
  // A tool link the robot's file names wins over the last link.
  ur.tool_link = "wrist_3_link";
  EXPECT_EQ(AdaptLinksToRobot(p, ur).end_effector_link, "wrist_3_link");
}

TEST(PlannerConstruction, RobotNeutralLinkNamesBecomeTheRobotsOwn) {
  PlannerParams p;
  p.end_effector_link = "";
  p.allowed_collisions = {{"<base>", "table"}, {"panda_link2", "pillar"}};
  // The Panda's file names its flange as the tool link: the same planner as
  // with the names written out.
  const Planner panda(testing::LoadPanda(), testing::LoadCell(), p);
  EXPECT_EQ(panda.params().end_effector_link, "panda_link8");
  const std::vector<std::pair<std::string, std::string>> pairs = {
      {"panda_link0", "table"}, {"panda_link1", "table"}, {"panda_link2", "pillar"}};
  EXPECT_EQ(panda.params().allowed_collisions, pairs);
  // The UR5e (plain URDF, no tool link said): its last link and its base.
  p.allowed_collisions = {{"<base>", "table"}};
  const Planner ur(collision::LoadRobotModel(std::string(IPLAN_SHARED_DIR) + "/robots/ur5e/ur5e.urdf"),
                   testing::LoadCell(), p);
  EXPECT_EQ(ur.params().end_effector_link, "tool0");
  const std::vector<std::pair<std::string, std::string>> base = {{"base_link_inertia", "table"},
                                                                   {"shoulder_link", "table"}};
  EXPECT_EQ(ur.params().allowed_collisions, base);
}

TEST(PlannerConstruction, RejectsBadParamsAndNames) {
  PlannerParams p;
  p.end_effector_link = "nope";
  try {
    Planner pl(testing::LoadPanda(), testing::LoadCell(), p);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'nope'"), std::string::npos);
  }
  p = PlannerParams{};
  p.num_optimizers = 0;
  EXPECT_THROW(Planner(testing::LoadPanda(), testing::LoadCell(), p), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::planning
