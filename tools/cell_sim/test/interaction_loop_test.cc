// The one-process cell loop: a robot task against a standing person, closed
// through the replanner, the monitor and the simulated robot. A person far
// away changes nothing; a person standing in the path is protected by the
// monitor alone when the planner knows nothing; the run is deterministic;
// a contact is told apart by what the robot was doing when it began (moving
// into the person, or standing still while the person moved into it); an
// episode runs the tasks its feed gives one after another, the cores
// keeping their state between them.
#include "tools/cell_sim/core/interaction_loop.h"

#include <cmath>

#include <gtest/gtest.h>

#include "iplan/collision/robot_model.h"
#include "iplan/planning/planner_params.h"

namespace iplan::cell_sim {
namespace {

const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config/";
const Eigen::VectorXd kHome = (Eigen::VectorXd(7) << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785).finished();
// tasks/table_top.yaml hand_over: the tool over the table towards the person.
const Eigen::VectorXd kHandOver = (Eigen::VectorXd(7) << -0.274, 0.417, 0.0, -1.68, 0.0, 2.097, 0.8).finished();

// A person standing still facing -x, torso at `torso`, the right hand
// `reach` m in front of the torso (body joint order of upper_body.yaml).
Eigen::Matrix3Xd Standing(const Eigen::Vector3d& torso, double reach) {
  Eigen::Matrix3Xd p(3, 9);
  p.col(0) = torso + Eigen::Vector3d(0, 0, 0.48);
  p.col(1) = torso + Eigen::Vector3d(0, 0, 0.30);
  p.col(2) = torso;
  p.col(3) = torso + Eigen::Vector3d(0, 0.18, 0.25);
  p.col(4) = torso + Eigen::Vector3d(-0.1, 0.22, 0.02);
  p.col(5) = torso + Eigen::Vector3d(-0.25, 0.2, -0.05);
  p.col(6) = torso + Eigen::Vector3d(0, -0.18, 0.25);
  p.col(7) = torso + Eigen::Vector3d(-0.5 * reach, -0.2, 0.05);
  p.col(8) = torso + Eigen::Vector3d(-reach, -0.15, -0.05);
  return p;
}

class InteractionLoopTest : public ::testing::Test {
 protected:
  InteractionLoopTest()
      : body_(collision::LoadHumanBodyParams(kConfig + "humans/upper_body.yaml")),
        monitor_(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"), body_.params(),
                 collision_risk::RiskParams{}) {
    planning::PlannerParams pp = planning::LoadPlannerParams(kConfig + "planner_replanning.yaml");
    pp.num_threads = 1;
    planner_ = std::make_unique<planning::Planner>(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                                                   collision::LoadSceneParams(kConfig + "scenes/cell.yaml"), pp);
    models_.planner = planner_.get();
    models_.body = &body_;
    models_.monitor = &monitor_;
    params_.max_duration = 8;
  }

  // A person standing still for the whole run, observed with 1 cm noise.
  PersonStream StandingPerson(const Eigen::Vector3d& torso, double reach) const {
    PersonStream s;
    s.joint_names = body_.params().joints;
    s.rate_hz = 30;
    const Eigen::Matrix3Xd p = Standing(torso, reach);
    for (int i = 0; i < 30 * 12; ++i) {
      s.truth.push_back(p);
      Eigen::Matrix3Xd o = p;
      o.row(0).array() += 0.01 * std::sin(0.7 * i);
      s.observed.push_back(o);
    }
    return s;
  }

  // "The person stays where they are": the true pose at every step, 5 cm.
  PredictionSource Holding(const PersonStream& s) {
    return [this, &s](int frame) {
      held_ = collision::JointMixture{};
      held_.t0_ns = SimTimeNs(s.stamp(frame));
      held_.time_step = 1.0 / 15;
      held_.num_steps = 15;
      held_.joint_names = s.joint_names;
      held_.actions = {"stand"};
      held_.probabilities = {1.0};
      held_.means.resize(1);
      held_.covariances.resize(1);
      for (int k = 0; k < 15; ++k) {
        for (int j = 0; j < 9; ++j) {
          held_.means[0].push_back(s.truth[static_cast<std::size_t>(frame)].col(j));
          held_.covariances[0].push_back(0.0025 * Eigen::Matrix3d::Identity());
        }
      }
      return &held_;
    };
  }

  TaskSetup HandOver() const {
    TaskSetup t;
    t.start_q = kHome;
    t.task.id = 1;
    t.task.name = "hand_over";
    t.task.goal = planning::Goal::Joint(kHandOver);
    t.task.time_limit = 6;
    return t;
  }

  // The centre (W) and radius of the robot sphere nearest the person's side
  // (largest x) at q.
  std::pair<Eigen::Vector3d, double> FrontSphere(const Eigen::VectorXd& q) const {
    const collision::RobotModel& robot = planner_->robot();
    collision::RobotData data(robot);
    collision::CalcForwardKinematics(robot, q, &data);
    Eigen::Index front = 0;
    for (Eigen::Index k = 1; k < data.p_WS.cols(); ++k) {
      if (data.p_WS(0, k) > data.p_WS(0, front)) front = k;
    }
    return {data.p_WS.col(front), robot.spheres[static_cast<std::size_t>(front)].radius};
  }

  collision::HumanBodyModel body_;
  collision_risk::RiskMonitor monitor_;
  std::unique_ptr<planning::Planner> planner_;
  CellModels models_;
  LoopParams params_;
  collision::JointMixture held_;
};

TEST_F(InteractionLoopTest, PersonFarAwayChangesNothing) {
  const PersonStream person = StandingPerson({2.5, 0.0, 0.25}, 0.3);
  const InteractionResult r = RunInteraction(models_, params_, HandOver(), person, Holding(person), Holding(person), nullptr);
  EXPECT_TRUE(r.finished) << r.reason;
  EXPECT_EQ(r.status, trajopt::TaskStatus::kSucceeded) << r.reason;
  EXPECT_GT(r.task_time, 0.5);
  EXPECT_LT(r.task_time, 5.0);
  EXPECT_EQ(r.protective_stops, 0) << r.first_stop_reason;
  EXPECT_DOUBLE_EQ(r.stop_time, 0.0);
  EXPECT_EQ(r.true_contacts, 0);
  EXPECT_GT(r.min_separation, 0.8);
  EXPECT_LT(r.max_bound, 1e-6);
  EXPECT_GT(r.planning_cycles, 5);
}

TEST_F(InteractionLoopTest, MonitorAloneKeepsTheRobotOffAPersonInItsPath) {
  // The right hand rests just beyond the hand-over pose; the planner gets no
  // prediction, the monitor the person's.
  const PersonStream person = StandingPerson({1.0, -0.1, 0.25}, 0.3);
  const InteractionResult r = RunInteraction(models_, params_, HandOver(), person, nullptr, Holding(person), nullptr);
  EXPECT_GE(r.protective_stops, 1);
  EXPECT_GT(r.stop_time, 0.5);
  EXPECT_FALSE(r.first_stop_reason.empty());
  EXPECT_EQ(r.true_contacts, 0);
  EXPECT_GT(r.min_separation, 0.0);
}

TEST_F(InteractionLoopTest, ResumesOnlyAfterEveryCauseHasBeenClearForTheDelay) {
  // In the path for 3 s, then gone to the far side of the room.
  PersonStream person = StandingPerson({1.0, -0.1, 0.25}, 0.3);
  const Eigen::Matrix3Xd away = Standing({3.0, 0.0, 0.25}, 0.3);
  for (int i = 90; i < person.num_frames(); ++i) person.truth[static_cast<std::size_t>(i)] = person.observed[static_cast<std::size_t>(i)] = away;
  std::vector<std::pair<double, std::string>> events;
  params_.trace = [&](double t, const std::string& e) {
    if (e.rfind("STOP", 0) == 0 || e.rfind("resume", 0) == 0) events.emplace_back(t, e);
  };
  const InteractionResult r = RunInteraction(models_, params_, HandOver(), person, nullptr, Holding(person), nullptr);
  ASSERT_GE(events.size(), 2u);
  double stopped_at = -1, last_resume = -1;
  for (const auto& [t, e] : events) {
    if (e.rfind("STOP", 0) == 0) {
      stopped_at = t;
    } else {
      ASSERT_GE(stopped_at, 0) << e;
      EXPECT_GE(t - stopped_at, params_.resume_delay - 1e-9) << "resumed " << t - stopped_at << " s after a stop: " << e;
      last_resume = t;
    }
  }
  EXPECT_GE(last_resume, 3.0 + params_.resume_delay - 1e-9);
  EXPECT_TRUE(r.finished) << r.reason;
  EXPECT_EQ(r.status, trajopt::TaskStatus::kSucceeded) << r.reason;
  EXPECT_EQ(r.true_contacts, 0);
}

TEST_F(InteractionLoopTest, SameInputsSameRun) {
  const PersonStream person = StandingPerson({1.0, -0.1, 0.25}, 0.3);
  const InteractionResult a = RunInteraction(models_, params_, HandOver(), person, Holding(person), Holding(person), nullptr);
  const InteractionResult b = RunInteraction(models_, params_, HandOver(), person, Holding(person), Holding(person), nullptr);
  EXPECT_EQ(a.finished, b.finished);
  EXPECT_EQ(a.task_time, b.task_time);
  EXPECT_EQ(a.protective_stops, b.protective_stops);
  EXPECT_EQ(a.stop_time, b.stop_time);
  EXPECT_EQ(a.min_separation, b.min_separation);
  EXPECT_EQ(a.max_bound, b.max_bound);
  EXPECT_EQ(a.planner_delay, b.planner_delay);
  EXPECT_EQ(a.planning_cycles, b.planning_cycles);
}

TEST_F(InteractionLoopTest, AContactWithTheRobotMovingCountsAsMoving) {
  // The right hand held where the hand-over puts the tool, a planner that
  // knows nothing of the person, and a monitor whose protective separation
  // is 0 (every ISO/TS 15066 term 0, no prediction): the robot drives into
  // the hand and stops only once it touches it.
  collision_risk::RiskParams blind;
  blind.ssm.measure_human_speed = false;
  blind.ssm.default_human_speed = 0;
  blind.ssm.reaction_time = 0;
  blind.ssm.stopping_time = 0;
  blind.ssm.stopping_distance = 0;
  blind.ssm.intrusion_distance = 0;
  blind.ssm.sensing_uncertainty = 0;
  blind.ssm.robot_uncertainty = 0;
  const collision_risk::RiskMonitor late(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                                         body_.params(), blind);
  models_.monitor = &late;
  const Eigen::Vector3d goal_tool = FrontSphere(kHandOver).first;
  const PersonStream person = StandingPerson(goal_tool + Eigen::Vector3d(0.3, 0.15, 0.05), 0.3);
  const InteractionResult r = RunInteraction(models_, params_, HandOver(), person, nullptr, nullptr, nullptr);
  ASSERT_GE(r.true_contacts, 1) << "min separation " << r.min_separation;
  EXPECT_EQ(r.robot_moving_contacts, r.true_contacts);
  EXPECT_EQ(r.robot_at_rest_contacts, 0);
  ASSERT_EQ(r.contact_speeds.size(), static_cast<std::size_t>(r.true_contacts));
  EXPECT_GT(r.contact_speeds.front(), kMovingContactSpeed);
  EXPECT_LT(r.min_separation, 0.0);
}

TEST_F(InteractionLoopTest, AHandMovingIntoTheRobotAtRestCountsAsAtRest) {
  // The hand 8 cm from the robot's front sphere at home keeps the monitor's
  // stop on from the start (the robot never moves); at 2.5 s it moves into
  // the sphere.
  const auto [centre, radius] = FrontSphere(kHome);
  const double hand_radius = 0.06;  // upper_body.yaml forearm spheres (the hand is one's centre)
  const Eigen::Vector3d near = centre + Eigen::Vector3d(radius + hand_radius + 0.08, 0, 0);
  const Eigen::Vector3d offset(0.3, 0.15, 0.05);  // torso from hand in Standing(torso, 0.3)
  PersonStream person = StandingPerson(near + offset, 0.3);
  const Eigen::Matrix3Xd touching = Standing(centre + offset, 0.3);
  for (int i = 75; i < person.num_frames(); ++i) {
    person.truth[static_cast<std::size_t>(i)] = person.observed[static_cast<std::size_t>(i)] = touching;
  }
  int resumes = 0;
  params_.trace = [&](double, const std::string& e) { resumes += e.rfind("resume", 0) == 0; };
  const InteractionResult r = RunInteraction(models_, params_, HandOver(), person, nullptr, Holding(person), nullptr);
  EXPECT_EQ(resumes, 0) << "the robot was meant to stay stopped";
  EXPECT_EQ(r.first_stop_reason, "stopped when the task was commanded");
  ASSERT_EQ(r.true_contacts, 1) << "min separation " << r.min_separation;
  EXPECT_EQ(r.robot_at_rest_contacts, 1);
  EXPECT_EQ(r.robot_moving_contacts, 0);
  ASSERT_EQ(r.contact_speeds.size(), 1u);
  EXPECT_LE(r.contact_speeds.front(), kMovingContactSpeed);
}

TEST_F(InteractionLoopTest, AnEpisodeRunsItsTasksInTurnFromWhereTheLastEnded) {
  // Home -> hand_over -> home, chosen when asked; the person far away.
  const PersonStream person = StandingPerson({2.5, 0.0, 0.25}, 0.3);
  params_.max_duration = 10;
  std::vector<std::pair<double, int>> asked;  // (t, frame)
  std::vector<double> ended;
  TaskFeed feed;
  feed.pause = 0.5;
  feed.next = [&](double t, int frame) -> std::optional<trajopt::TaskSpec> {
    asked.emplace_back(t, frame);
    trajopt::TaskSpec s = HandOver().task;
    s.id = static_cast<uint32_t>(asked.size());
    if (asked.size() == 2) s.goal = planning::Goal::Joint(kHome);
    return s;
  };
  feed.done = [&](double t, int, const trajopt::TaskOutcome& o) {
    EXPECT_EQ(o.id, ended.size() + 1);
    ended.push_back(t);
    return ended.size() < 2;
  };
  const EpisodeResult e = RunEpisode(models_, params_, kHome, feed, person, Holding(person), Holding(person), nullptr);
  ASSERT_EQ(e.tasks.size(), 2u);
  ASSERT_EQ(asked.size(), 2u);
  ASSERT_EQ(ended.size(), 2u);
  EXPECT_TRUE(e.ended_by_feed);
  EXPECT_NEAR(asked[0].first, params_.task_start, 1e-9);
  // The newest frame at 30 Hz when asked.
  EXPECT_EQ(asked[0].second, static_cast<int>(std::floor(asked[0].first * 30 + 1e-6)));
  // The second task: at the first planning step at least the pause after the first outcome.
  EXPECT_GE(asked[1].first, ended[0] + feed.pause - 1e-9);
  EXPECT_LT(asked[1].first, ended[0] + feed.pause + 0.1 + 1e-9);
  for (const InteractionResult& r : e.tasks) {
    EXPECT_TRUE(r.finished) << r.reason;
    EXPECT_EQ(r.status, trajopt::TaskStatus::kSucceeded) << r.reason;
    EXPECT_EQ(r.protective_stops, 0);
    EXPECT_LT(r.wait_time, 0.5) << "standing still with nobody near";
  }
  EXPECT_NEAR(e.tasks[1].command_time, asked[1].first, 1e-9);
  EXPECT_NEAR(e.duration, ended[1] - asked[0].first, 1e-9);
  EXPECT_EQ(e.robot_moving_contacts + e.robot_at_rest_contacts, 0);
  EXPECT_GT(e.min_separation, 0.8);

  // With one task, RunInteraction is that episode's first task.
  const InteractionResult one = RunInteraction(models_, params_, HandOver(), person, Holding(person), Holding(person), nullptr);
  EXPECT_EQ(one.task_time, e.tasks[0].task_time);
  EXPECT_EQ(one.planning_cycles, e.tasks[0].planning_cycles);
  EXPECT_EQ(one.min_separation, e.tasks[0].min_separation);
}

TEST_F(InteractionLoopTest, AnEpisodeThatOutrunsItsLimitEndsWithTheTaskUnfinished) {
  // The hand rests where the hand-over goes; the monitor keeps stopping the robot.
  const PersonStream person = StandingPerson({1.0, -0.1, 0.25}, 0.3);
  params_.max_duration = 3;
  TaskFeed feed;
  feed.next = [&](double, int) -> std::optional<trajopt::TaskSpec> { return HandOver().task; };
  feed.done = [](double, int, const trajopt::TaskOutcome&) { return true; };
  const EpisodeResult e = RunEpisode(models_, params_, kHome, feed, person, nullptr, Holding(person), nullptr);
  ASSERT_EQ(e.tasks.size(), 1u);
  EXPECT_FALSE(e.ended_by_feed);
  EXPECT_FALSE(e.tasks[0].finished);
  EXPECT_NEAR(e.duration, 3.0, 1e-9);
  EXPECT_EQ(e.tasks[0].task_time, 3.0);
  EXPECT_GT(e.tasks[0].stop_time + e.tasks[0].wait_time, 1.0);
  feed.pause = -1;
  EXPECT_THROW(RunEpisode(models_, params_, kHome, feed, person, nullptr, nullptr, nullptr), std::invalid_argument);
}

TEST_F(InteractionLoopTest, PersonStreamInterpolatesAndIsChecked) {
  PersonStream s;
  s.joint_names = {"a"};
  s.rate_hz = 10;
  s.truth = {Eigen::Matrix3Xd::Zero(3, 1), Eigen::Matrix3Xd::Ones(3, 1)};
  s.observed = s.truth;
  EXPECT_EQ(s.Validate(), "");
  Eigen::Matrix3Xd p;
  s.TrueAt(0.05, &p);
  EXPECT_NEAR(p(1, 0), 0.5, 1e-12);
  s.TrueAt(3.0, &p);  // held after the last frame
  EXPECT_EQ(p(2, 0), 1.0);
  s.TrueAt(-1.0, &p);
  EXPECT_EQ(p(0, 0), 0.0);
  s.observed.pop_back();
  EXPECT_NE(s.Validate(), "");
  // A person whose joints are not the body's is refused.
  EXPECT_THROW(RunInteraction(models_, params_, HandOver(), s, nullptr, nullptr, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::cell_sim
