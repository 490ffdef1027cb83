// The replanning loop with an ideal robot that follows every published plan:
// tasks finish, consecutive plans join without jumps, a person standing on
// the goal makes the robot wait (reported as delay), and unreachable goals
// and cancellations end the task with the right outcome.
#include <algorithm>
#include <iostream>
#include <limits>

#include <gtest/gtest.h>

#include "iplan/core/params.h"
#include "replanner_fixture.h"

namespace iplan::trajopt {
namespace {

TEST_F(ReplannerTest, ReachesAJointGoalWithoutDelay) {
  int64_t t = 100 * kSec;
  SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  EXPECT_EQ(replanner_.StartTask({7, "reach", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
  const auto o = Run(&t, 80);
  ASSERT_TRUE(o.has_value()) << "no outcome in 8 s";
  EXPECT_EQ(o->status, TaskStatus::kSucceeded) << o->reason;
  EXPECT_EQ(o->id, 7u);
  EXPECT_EQ(o->delay, 0.0);
  EXPECT_EQ(o->num_waits, 0u);
  EXPECT_GT(o->duration, 0.5);
  EXPECT_GT(o->planning_time_p50, 0.0);
  EXPECT_FALSE(replanner_.busy());
}

TEST_F(ReplannerTest, TaskWithARetreatEndsOnlyWhenTheRobotHasWithdrawn) {
  int64_t t = 100 * kSec;
  SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  const auto plain = [&] {
    EXPECT_EQ(replanner_.StartTask({7, "reach", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
    return Run(&t, 80);
  }();
  ASSERT_TRUE(plain.has_value());
  ASSERT_EQ(plain->status, TaskStatus::kSucceeded) << plain->reason;
  EXPECT_EQ(statuses_.back(), "goal reached");

  // From the goal, reach it again (no motion) and withdraw to Ready.
  statuses_.clear();
  visited_.clear();
  TaskSpec hand_over{8, "hand_over", planning::Goal::Joint(Goal()), 0, Ready()};
  EXPECT_EQ(replanner_.StartTask(hand_over, t), std::nullopt);
  const auto o = Run(&t, 80);
  ASSERT_TRUE(o.has_value()) << "no outcome in 8 s";
  EXPECT_EQ(o->status, TaskStatus::kSucceeded) << o->reason;
  EXPECT_EQ(o->id, 8u);
  EXPECT_EQ(o->delay, 0.0);
  EXPECT_EQ(statuses_.back(), "retreat reached");
  EXPECT_EQ(std::count_if(statuses_.begin(), statuses_.end(),
                          [](const std::string& s) { return s.rfind("goal reached, retreating", 0) == 0; }),
            1);
  ASSERT_FALSE(visited_.empty());
  EXPECT_LT((visited_.back() - Ready()).cwiseAbs().maxCoeff(), ReplannerParams{}.goal_tolerance);
  // The withdrawal is part of the task: it took about as long as the way there.
  EXPECT_GT(o->duration, 0.5 * plain->duration);

  // A retreat of the wrong size is refused before anything moves.
  TaskSpec wrong{9, "bad", planning::Goal::Joint(Goal()), 0, Eigen::VectorXd::Zero(6)};
  EXPECT_THROW(replanner_.StartTask(wrong, t), std::invalid_argument);
  EXPECT_FALSE(replanner_.busy());
}

TEST_F(ReplannerTest, MotionLongerThanTheHorizonAllowsStillArrives) {
  // The service's replanning horizon (1.5 s) is too short for 2.8 rad of
  // joint 1 within its 2.175 rad/s limit: the task gets a longer plan
  // instead of holding for ever.
  const planning::Planner short_horizon(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                                        collision::LoadSceneParams(kConfig + "scenes/cell.yaml"),
                                        planning::LoadPlannerParams(kConfig + "planner_replanning.yaml"));
  ASSERT_LT(short_horizon.params().horizon * 2.175, 2.8 * 1.2);
  Replanner replanner(short_horizon, body_, ReplannerParams{});
  Eigen::VectorXd from(7), to(7);
  from << -1.4, 0.0, 0.0, -2.2, 0.0, 2.2, 0.8;
  to << 1.4, 0.0, 0.0, -2.2, 0.0, 2.2, 0.8;
  int64_t t = 100 * kSec;
  std::optional<CycleResult> last;
  auto state = [&](int64_t at) {
    const Eigen::VectorXd q = last ? At(*last, at) : from;
    const Eigen::VectorXd q2 = last ? At(*last, at + kSec / 100) : from;
    const Eigen::VectorXd qd = (q2 - q) / 0.01;
    ASSERT_EQ(replanner.UpdateRobotState(at, replanner.joint_names(), std::vector<double>(q.data(), q.data() + 7),
                                         std::vector<double>(qd.data(), qd.data() + 7)),
              std::nullopt);
  };
  state(t);
  ASSERT_EQ(replanner.StartTask({3, "across", planning::Goal::Joint(to), 0}, t), std::nullopt);
  std::optional<TaskOutcome> outcome;
  for (int k = 0; k < 80 && !outcome; ++k) {
    CycleResult c = replanner.Cycle(t);
    outcome = c.outcome;
    if (c.publish) {
      EXPECT_FALSE(c.waiting) << "cycle " << k << ": " << c.status;
      for (int i = 0; i + 1 < c.positions.cols(); ++i) {  // within the velocity limits (2.175 rad/s, joints 1-4)
        EXPECT_LE((c.positions.col(i + 1) - c.positions.col(i)).head(4).cwiseAbs().maxCoeff() / c.dt, 2.175 + 1e-6)
            << "cycle " << k << " waypoint " << i;
      }
      last = c;
    }
    t += kSec / 10;
    state(t);
  }
  ASSERT_TRUE(outcome.has_value()) << "no outcome in 8 s";
  EXPECT_EQ(outcome->status, TaskStatus::kSucceeded) << outcome->reason;
  EXPECT_EQ(outcome->delay, 0.0);
  EXPECT_GT(outcome->duration, 2.8 / 2.175);
}

// Reaches with an ideal robot that follows every plan, under given planner
// settings (the cell's replanning ones, changed).
class ReplannerArrivalTest : public ReplannerTest {
 protected:
  struct Reach {
    double first_plan = -1;  ///< s, duration of the first published plan
    double task = 1e9;       ///< s, the task's duration (1e9: no outcome in 8 s)
  };
  Reach IdealReach(const planning::PlannerParams& params, const Eigen::VectorXd& goal) {
    const planning::Planner planner(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                                    collision::LoadSceneParams(kConfig + "scenes/cell.yaml"), params);
    Replanner replanner(planner, body_, ReplannerParams{});
    int64_t t = 100 * kSec;
    std::optional<CycleResult> last;
    Reach out;
    auto state = [&](int64_t at) {
      const Eigen::VectorXd q = last ? At(*last, at) : Ready();
      const Eigen::VectorXd qd = last ? Eigen::VectorXd((At(*last, at + kSec / 100) - q) / 0.01) : Eigen::VectorXd::Zero(7);
      EXPECT_EQ(replanner.UpdateRobotState(at, replanner.joint_names(), std::vector<double>(q.data(), q.data() + 7),
                                           std::vector<double>(qd.data(), qd.data() + 7)),
                std::nullopt);
    };
    state(t);
    EXPECT_EQ(replanner.StartTask({21, "reach", planning::Goal::Joint(goal), 0}, t), std::nullopt);
    for (int k = 0; k < 80; ++k) {
      CycleResult c = replanner.Cycle(t);
      if (c.outcome) {
        EXPECT_EQ(c.outcome->status, TaskStatus::kSucceeded) << c.outcome->reason;
        out.task = c.outcome->duration;
        return out;
      }
      if (c.publish) {
        if (out.first_plan < 0) out.first_plan = static_cast<double>(c.positions.cols() - 1) * c.dt;
        last = c;
      }
      t += kSec / 10;
      state(t);
    }
    ADD_FAILURE() << "no outcome in 8 s";
    return out;
  }
};

// With keep_arrival (the cell's replanning settings) a replan keeps the
// arrival of the plan before it: the motion ends about a horizon after it
// started. Without it every replan plans a whole horizon to the goal again,
// so the arrival recedes and the end of the motion decays.
TEST_F(ReplannerArrivalTest, AReplanKeepsThePlansArrivalInsteadOfRecedingIt) {
  planning::PlannerParams params = planning::LoadPlannerParams(kConfig + "planner_replanning.yaml");
  ASSERT_TRUE(params.keep_arrival);
  params.motion_speed_fraction = 0;  // every new goal gets the whole horizon (as shipped): keep_arrival alone
  const double kept = IdealReach(params, Goal()).task;
  params.keep_arrival = false;
  const double receding = IdealReach(params, Goal()).task;
  std::cout << "reach Ready -> Goal: " << kept << " s keeping the arrival, " << receding << " s receding\n";
  // The horizon, the cycle in which the goal is seen reached and one more.
  EXPECT_LE(kept, params.horizon + 0.2 + 1e-9);
  EXPECT_GT(receding, kept + 0.3);
}

// With motion_speed_fraction (off in the cell's replanning settings) the
// first plan to a new goal takes the time its distance needs, at least
// min_motion_time; a motion the horizon is too short for keeps the horizon.
TEST_F(ReplannerArrivalTest, APlanToANewGoalTakesTheTimeItsDistanceNeeds) {
  planning::PlannerParams params = planning::LoadPlannerParams(kConfig + "planner_replanning.yaml");
  ASSERT_LT(params.min_motion_time, params.horizon);
  // Ready to Goal: 0.6 rad of joint 1 at most, 0.4 s at half its 2.175 rad/s
  // limit with the peak factor 1.5: the floor, min_motion_time.
  params.motion_speed_fraction = 0.5;
  const Reach fitted = IdealReach(params, Goal());
  // 2 rad of joint 1 needs 2.76 s at half its limit: the horizon caps it.
  Eigen::VectorXd far = Ready();
  far[0] += 2.0;
  const Reach far_reach = IdealReach(params, far);
  params.motion_speed_fraction = 0.0;
  const Reach whole = IdealReach(params, Goal());
  std::cout << "Ready -> Goal: first plan " << fitted.first_plan << " s, task " << fitted.task << " s (fitted); "
            << whole.first_plan << " s, " << whole.task << " s (the whole horizon)\n";
  EXPECT_NEAR(fitted.first_plan, params.min_motion_time, 1e-9);
  EXPECT_NEAR(whole.first_plan, params.horizon, 1e-9);
  EXPECT_LT(fitted.task, whole.task - 0.2);
  EXPECT_NEAR(far_reach.first_plan, params.horizon, 1e-9);
  EXPECT_LT(far_reach.task, 8.0);
}

TEST_F(ReplannerTest, PersonOnTheGoalMakesTheRobotWaitThenItArrives) {
  int64_t t = 100 * kSec;
  SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  collision::RobotData data(planner_.robot());
  collision::CalcForwardKinematics(planner_.robot(), Goal(), &data);
  const Eigen::Vector3d goal_hand = data.X_WL.back().translation();
  const int64_t leaves = t + 25 * kSec / 10;
  ASSERT_EQ(replanner_.StartTask({8, "reach_blocked", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
  const auto o = Run(&t, 150, [&](int64_t now) {
    const Eigen::Vector3d hand = now < leaves ? goal_hand : Eigen::Vector3d(1.8, 0.8, 1.0);
    ASSERT_EQ(replanner_.UpdatePrediction(PersonAt(now, hand)), std::nullopt);
  });
  ASSERT_TRUE(o.has_value()) << "no outcome in 15 s";
  EXPECT_EQ(o->status, TaskStatus::kSucceeded) << o->reason;
  EXPECT_GT(o->num_waits, 0u);
  // Blocked for 2.5 s of a task that takes about 1 s unobstructed.
  EXPECT_GT(o->delay, 1.0);
  EXPECT_LE(o->delay, o->duration);
  EXPECT_GT(o->duration, 2.5);  // it could not arrive before the person left
  EXPECT_LT(o->max_collision_bound, 0.05);
}

TEST_F(ReplannerTest, RobotOffThePlanIsReplannedFromItsState) {
  int64_t t = 100 * kSec;
  SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  ASSERT_EQ(replanner_.StartTask({12, "reach", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
  CycleResult c = replanner_.Cycle(t);
  ASSERT_TRUE(c.publish);
  // The robot was stopped: it stays at Ready while the plan moved on.
  for (int k = 0; k < 5; ++k) {
    t += kSec / 10;
    SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  }
  c = replanner_.Cycle(t);
  ASSERT_TRUE(c.publish);
  EXPECT_EQ(c.status.rfind("robot off the plan", 0), 0u) << c.status;
  EXPECT_LT((c.positions.col(0) - Ready()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(c.start_ns, t);
}

// A robot the separation monitor slows down (its path time-scaled) is behind
// the plan's timing, on its path, and moving along it: the replanner re-times
// the plan to where the robot is (the frozen prefix continues from there),
// rather than planning from the state as for a robot off the plan; a robot
// that stands at the same place is not re-timed.
TEST_F(ReplannerTest, ARobotSlowedDownOnItsPathIsReTimedNotReplannedFromRest) {
  // The cell's replanning settings: a 1.5 s horizon, so the arm is fast.
  const planning::Planner cell(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                               collision::LoadSceneParams(kConfig + "scenes/cell.yaml"),
                               planning::LoadPlannerParams(kConfig + "planner_replanning.yaml"));
  Replanner replanner(cell, body_, ReplannerParams{});
  int64_t t = 100 * kSec;
  auto set_state = [&](int64_t at, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    ASSERT_EQ(replanner.UpdateRobotState(at, replanner.joint_names(), std::vector<double>(q.data(), q.data() + 7),
                                         std::vector<double>(qd.data(), qd.data() + 7)),
              std::nullopt);
  };
  set_state(t, Ready(), Eigen::VectorXd::Zero(7));
  ASSERT_EQ(replanner.StartTask({13, "reach", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
  CycleResult c;
  for (int k = 0; k < 4; ++k) {  // under way at full speed
    c = replanner.Cycle(t);
    ASSERT_TRUE(c.publish && !c.outcome) << c.status;
    t += kSec / 10;
    const Eigen::VectorXd q = At(c, t);
    set_state(t, q, (At(c, t + kSec / 100) - q) / 0.01);
  }
  c = replanner.Cycle(t);
  ASSERT_TRUE(c.publish) << c.status;
  // Run at a tenth of the plan's speed from here: 0.1 s later the robot is
  // where the plan is 0.01 s after it, moving at a tenth of its speed.
  const int64_t path = t + kSec / 100;
  t += kSec / 10;
  const Eigen::VectorXd q = At(c, path);
  ASSERT_GT((At(c, t) - q).cwiseAbs().maxCoeff(), 0.5 * ReplannerParams{}.max_tracking_error)
      << "the lag must be large enough to matter";
  const Eigen::VectorXd v = (At(c, path + kSec / 100) - q) / 0.01 / 10;
  set_state(t, q, v);
  const CycleResult slowed = replanner.Cycle(t);
  EXPECT_NE(slowed.status.find("re-timed"), std::string::npos) << slowed.status;
  EXPECT_EQ(slowed.status.find("robot off the plan"), std::string::npos) << slowed.status;
  EXPECT_LT((slowed.positions.col(0) - q).cwiseAbs().maxCoeff(), 0.02) << "the plan continues from the robot";
  // The same place without motion (a robot stopped there) is not re-timed.
  Replanner other(cell, body_, ReplannerParams{});
  int64_t t2 = 100 * kSec;
  const Eigen::VectorXd ready = Ready();
  ASSERT_EQ(other.UpdateRobotState(t2, other.joint_names(), std::vector<double>(ready.data(), ready.data() + 7),
                                   std::vector<double>(7, 0.0)),
            std::nullopt);
  ASSERT_EQ(other.StartTask({13, "reach", planning::Goal::Joint(Goal()), 0}, t2), std::nullopt);
  for (int k = 0; k < 5; ++k) {
    const CycleResult oc = other.Cycle(t2);
    t2 += kSec / 10;
    const Eigen::VectorXd oq = At(oc, k < 4 ? t2 : t2 - kSec * 9 / 100);
    const Eigen::VectorXd ov = k < 4 ? Eigen::VectorXd((At(oc, t2 + kSec / 100) - oq) / 0.01) : Eigen::VectorXd::Zero(7);
    ASSERT_EQ(other.UpdateRobotState(t2, other.joint_names(), std::vector<double>(oq.data(), oq.data() + 7),
                                     std::vector<double>(ov.data(), ov.data() + 7)),
              std::nullopt);
  }
  EXPECT_EQ(other.Cycle(t2).status.find("re-timed"), std::string::npos);
}

// Patience (ReplannerParams::ssm_patience): a person who stays beside the
// goal, outside the monitor's S_p there but inside S_p + ssm_margin, holds
// the task off for ever without it; with it, the margin shrinks with the
// task's delay, and the robot arrives once the person has delayed it long
// enough, still outside S_p.
TEST_F(ReplannerTest, PatienceLetsARobotHeldOffByAStayingPersonArriveOutsideTheProtectiveSeparation) {
  const planning::PlannerParams pp = planning::LoadPlannerParams(kConfig + "planner_replanning.yaml");
  ASSERT_TRUE(pp.predict_ssm);
  ASSERT_NEAR(pp.ssm_margin, 0.08, 1e-12);
  const planning::Planner predicting(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                                     collision::LoadSceneParams(kConfig + "scenes/cell.yaml"), pp);
  const collision::RobotModel& robot = predicting.robot();
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, Goal(), &d);
  const Eigen::Vector3d tool = d.p_WS.col(static_cast<Eigen::Index>(robot.spheres.size()) - 1);
  // Smallest surface distance between the robot at the goal and the person
  // whose hand is `offset` m beyond the tool along x.
  auto gap = [&](double offset) {
    const collision::JointMixture m = PersonAt(0, tool + Eigen::Vector3d(offset, 0, 0));
    Eigen::Matrix3Xd joints(3, static_cast<Eigen::Index>(m.joint_names.size()));
    for (std::size_t j = 0; j < m.joint_names.size(); ++j) joints.col(static_cast<Eigen::Index>(j)) = m.means[0][j];
    double best = std::numeric_limits<double>::infinity();
    for (int h = 0; h < body_.num_spheres(); ++h) {
      for (std::size_t k = 0; k < robot.spheres.size(); ++k) {
        best = std::min(best, (d.p_WS.col(static_cast<Eigen::Index>(k)) - body_.SphereCentre(h, joints)).norm() -
                                  robot.spheres[k].radius - body_.spheres()[static_cast<std::size_t>(h)].radius);
      }
    }
    return best;
  };
  // The hand placed so that the gap at the goal is S_p of a still person and
  // robot (0.17 m) + 0.04 m: half the planner's margin.
  double lo = 0.0, hi = 0.8;
  for (int i = 0; i < 60; ++i) (gap(0.5 * (lo + hi)) < 0.21 ? lo : hi) = 0.5 * (lo + hi);
  const Eigen::Vector3d hand = tool + Eigen::Vector3d(hi, 0, 0);
  ASSERT_NEAR(gap(hi), 0.21, 1e-6);
  // stop_at: the cycle at which the robot is in protective stop for one
  // cycle (-1: never).
  auto run = [&](double patience, double* closest, int stop_at = -1) {
    ReplannerParams rp;
    rp.ssm_patience = patience;
    Replanner replanner(predicting, body_, rp);
    int64_t t = 100 * kSec;
    Eigen::VectorXd q = Ready();
    std::vector<double> zero(7, 0.0);
    EXPECT_EQ(replanner.UpdateRobotState(t, replanner.joint_names(), std::vector<double>(q.data(), q.data() + 7), zero),
              std::nullopt);
    EXPECT_EQ(replanner.StartTask({14, "reach", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
    for (int k = 0; k < 80; ++k) {
      EXPECT_EQ(replanner.UpdatePrediction(PersonAt(t, hand)), std::nullopt);
      replanner.SetRobotStopped(k == stop_at);
      const CycleResult c = replanner.Cycle(t);
      if (c.outcome) return c.outcome;
      t += kSec / 10;
      if (c.publish && k != stop_at) q = At(c, t);
      collision::RobotData r(robot);
      collision::CalcForwardKinematics(robot, q, &r);
      *closest = std::min(*closest, (r.p_WS.col(static_cast<Eigen::Index>(robot.spheres.size()) - 1) - hand).norm());
      EXPECT_EQ(replanner.UpdateRobotState(t, replanner.joint_names(), std::vector<double>(q.data(), q.data() + 7), zero),
                std::nullopt);
    }
    return std::optional<TaskOutcome>();
  };
  double closest_without = std::numeric_limits<double>::infinity(), closest_with = closest_without;
  EXPECT_FALSE(run(0.0, &closest_without).has_value()) << "without patience the person holds the task off";
  const std::optional<TaskOutcome> o = run(1.5, &closest_with);
  ASSERT_TRUE(o.has_value()) << "with patience the robot arrives within 8 s";
  EXPECT_EQ(o->status, TaskStatus::kSucceeded) << o->reason;
  EXPECT_GT(o->delay, 0.5 * 1.5) << "not before the margin has shrunk to what the gap allows";
  EXPECT_LT(closest_with, closest_without);
  // A protective stop restarts patience: stopped for one cycle just before
  // it would have arrived, the robot waits for the margin to shrink again
  // (half the patience at least) instead of going straight back in.
  const int arrival = static_cast<int>(std::lround(o->duration * 10));
  double closest_stopped = std::numeric_limits<double>::infinity();
  const std::optional<TaskOutcome> stopped = run(1.5, &closest_stopped, arrival - 3);
  ASSERT_TRUE(stopped.has_value()) << "with patience the robot still arrives";
  EXPECT_EQ(stopped->status, TaskStatus::kSucceeded) << stopped->reason;
  EXPECT_GT(stopped->duration, o->duration + 0.5 * 1.5) << "patience restarted at the stop";
}

TEST_F(ReplannerTest, RobotStatesOutsideTheJointLimitsAreRefused) {
  const std::vector<std::string> names = replanner_.joint_names();
  auto update = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    return replanner_.UpdateRobotState(kSec, names, std::vector<double>(q.data(), q.data() + q.size()),
                                       std::vector<double>(qd.data(), qd.data() + qd.size()));
  };
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  Eigen::VectorXd q = Ready();
  q[1] = 100.0;  // panda_joint2
  const auto why = update(q, zero);
  ASSERT_TRUE(why.has_value());
  EXPECT_EQ(why->rfind("joint state: joint 'panda_joint2' at 100 rad is outside its limits", 0), 0u) << *why;
  // Refused states are not planned from.
  EXPECT_EQ(replanner_.Cycle(kSec).status, "waiting for a current robot state");
  // Beyond the limit by less than the tolerance (panda_joint2 upper 1.7628 rad) is accepted.
  q[1] = 1.7628 + 0.9 * ReplannerParams{}.joint_limit_tolerance;
  EXPECT_EQ(update(q, zero), std::nullopt);
  // Velocities: panda_joint1's limit is 2.175 rad/s.
  Eigen::VectorXd qd = zero;
  qd[0] = 10.0;
  const auto fast = update(Ready(), qd);
  ASSERT_TRUE(fast.has_value());
  EXPECT_EQ(fast->rfind("joint state: joint 'panda_joint1' at 10 rad/s is beyond", 0), 0u) << *fast;
  qd[0] = 2.175;
  EXPECT_EQ(update(Ready(), qd), std::nullopt);
}

TEST_F(ReplannerTest, UnreachablePoseFailsAndCancelEndsTheTask) {
  int64_t t = 100 * kSec;
  SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  ASSERT_EQ(replanner_.StartTask({9, "too_far", planning::Goal::Pose({3.0, 0, 0.5}, Eigen::Quaterniond::Identity()), 0}, t),
            std::nullopt);
  const auto o = Run(&t, 5);
  ASSERT_TRUE(o.has_value());
  EXPECT_EQ(o->status, TaskStatus::kFailed);
  EXPECT_FALSE(o->reason.empty());
  ASSERT_EQ(replanner_.StartTask({10, "a", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);
  EXPECT_EQ(replanner_.StartTask({10, "a", planning::Goal::Joint(Goal()), 0}, t), std::nullopt);  // repeat: ignored
  EXPECT_EQ(replanner_.current_task_id(), 10u);
  const auto replaced = replanner_.StartTask({11, "b", planning::Goal::Joint(Ready()), 0}, t);
  ASSERT_TRUE(replaced.has_value());
  EXPECT_EQ(replaced->id, 10u);
  EXPECT_EQ(replaced->status, TaskStatus::kCancelled);
  EXPECT_EQ(replanner_.CancelTask(99, t), std::nullopt);
  const auto cancelled = replanner_.CancelTask(11, t);
  ASSERT_TRUE(cancelled.has_value());
  EXPECT_EQ(cancelled->status, TaskStatus::kCancelled);
}

TEST_F(ReplannerTest, AnObstacleAppearingMidTaskIsPlannedAround) {
  // Joint 1 sweeping the hand low across the table (as obstacle_avoidance_test).
  Eigen::VectorXd start(7), goal(7);
  start << 0.45, 0.2, 0.0, -2.2, 0.0, 2.4, 0.8;
  goal << -0.75, 0.2, 0.0, -2.2, 0.0, 2.4, 0.8;
  int64_t t = 100 * kSec;
  SetState(t, start, Eigen::VectorXd::Zero(7));
  ASSERT_EQ(replanner_.StartTask({1, "free", planning::Goal::Joint(goal), 0}, t), std::nullopt);
  ASSERT_TRUE(Run(&t, 80).has_value());
  // A box on the table under the hand where the free run was furthest from
  // both its ends.
  collision::RobotData d(planner_.robot());
  const int hand_link = planner_.robot().FindLink("panda_hand");
  auto hand_at = [&](const Eigen::VectorXd& q) {
    collision::CalcForwardKinematics(planner_.robot(), q, &d);
    return Eigen::Vector3d(d.X_WL[hand_link].translation());
  };
  const Eigen::Vector3d first = hand_at(visited_.front()), last = hand_at(visited_.back());
  Eigen::Vector3d hand = first;
  for (const auto& q : visited_) {
    const Eigen::Vector3d p = hand_at(q);
    if (std::min((p - first).norm(), (p - last).norm()) > std::min((hand - first).norm(), (hand - last).norm())) hand = p;
  }
  collision::SceneObject box;
  box.name = "obstacle 1";
  box.size = Eigen::Vector3d(0.12, 0.12, hand.z() - 0.05);
  box.X_WO.translation() = Eigen::Vector3d(hand.x(), hand.y(), 0.5 * box.size.z());
  double free_clearance = std::numeric_limits<double>::infinity();
  for (const auto& q : visited_) free_clearance = std::min(free_clearance, planner_.CalcClearance(q, {box}));
  ASSERT_LT(free_clearance, -0.02);
  // The same task again; the box is seen after 0.2 s.
  visited_.clear();
  t += 10 * kSec;
  SetState(t, start, Eigen::VectorXd::Zero(7));
  ASSERT_EQ(replanner_.StartTask({2, "box", planning::Goal::Joint(goal), 0}, t), std::nullopt);
  const int64_t appear = t + 2 * kSec / 10;
  const auto o = Run(&t, 100, [&](int64_t now) {
    if (now == appear) replanner_.SetObstacles({box});
  });
  ASSERT_TRUE(o.has_value()) << "no outcome in 10 s";
  EXPECT_EQ(o->status, TaskStatus::kSucceeded) << o->reason;
  double clearance = std::numeric_limits<double>::infinity();
  for (const auto& q : visited_) clearance = std::min(clearance, planner_.CalcClearance(q, {box}));
  EXPECT_GE(clearance, 0.0);
}

TEST(ReplannerParams, TheDocumentedDefaultsAreTheDeclaredOnes) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(ReplannerParams{})),
            "");
}

TEST_F(ReplannerTest, PlansAgainstEveryFreshPersonAndDropsStaleOnes) {
  int64_t t = 100 * kSec;
  SetState(t, Ready(), Eigen::VectorXd::Zero(7));
  TaskSpec task;
  task.id = 1;
  task.goal = planning::Goal::Joint(Goal());
  replanner_.StartTask(task, t);
  // Two people far from the path (behind the robot's reach), bodies 3 and 8.
  ASSERT_EQ(replanner_.UpdatePrediction(3, PersonAt(t, {1.6, 0.8, 0.3})), std::nullopt);
  ASSERT_EQ(replanner_.UpdatePrediction(8, PersonAt(t, {1.6, -0.8, 0.3})), std::nullopt);
  // Body 3's older prediction is refused; its newer one stays.
  const auto late = replanner_.UpdatePrediction(3, PersonAt(t - kSec / 10, {0.5, 0.0, 0.3}));
  ASSERT_TRUE(late);
  EXPECT_NE(late->find("out of order"), std::string::npos) << *late;
  CycleResult c = replanner_.Cycle(t);
  EXPECT_EQ(c.num_people, 2) << c.status;
  EXPECT_EQ(c.prediction_t0_ns, t);
  EXPECT_LT(c.max_bound, 1e-6) << "neither person is near the path";
  // 0.4 s later body 8 is seen again, body 3 is not: at 0.6 s body 3's
  // prediction is older than stale_after (0.5 s) and no longer planned against.
  ASSERT_EQ(replanner_.UpdatePrediction(8, PersonAt(t + 4 * kSec / 10, {1.6, -0.8, 0.3})), std::nullopt);
  SetState(t + 6 * kSec / 10, At(c, t + 6 * kSec / 10), Eigen::VectorXd::Zero(7));
  c = replanner_.Cycle(t + 6 * kSec / 10);
  EXPECT_EQ(c.num_people, 1) << c.status;
  EXPECT_EQ(c.prediction_t0_ns, t + 4 * kSec / 10);
}

}  // namespace
}  // namespace iplan::trajopt
