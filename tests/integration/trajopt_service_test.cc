// iplan-trajopt and iplan-robot-sim as separate processes (Cyclone and Fast
// DDS); this process sends a task and scripts the person. The service
// publishes a trajectory every cycle and an outcome at the end; with a person
// standing on the goal the outcome reports waits and delay, and the simulated
// robot never touches the person's true body; a task with a retreat ends
// there, and a retreat of the wrong size is refused. The test process plays
// the supervisor (commands and the robot's only permit), intent and the
// simulated person, entitled to by the services' --set overrides. A command
// repeated after its task ended is answered with the same outcome again (how
// a supervisor that missed it catches up); a stranger's command changes
// nothing.
#include <signal.h>

#include <cmath>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "iplan/collision/robot_model.h"
#include "iplan/framework/node.h"
#include "cell_harness.h"
#include "test_messages.h"
#include "test_node.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const std::vector<std::string>& kJoints = kUpperBodyJoints;
const std::vector<double> kGoal = {0.6, -0.2, 0.0, -2.0, 0.0, 1.9, 0.8};

std::vector<Eigen::Vector3d> PersonWithHandAt(const Eigen::Vector3d& hand) {
  const Eigen::Vector3d torso = hand + Eigen::Vector3d(0.35, 0.1, 0.1);
  return {torso + Eigen::Vector3d(0, 0, 0.48), torso + Eigen::Vector3d(0, 0, 0.3), torso,
          torso + Eigen::Vector3d(0, -0.18, 0.25), torso + Eigen::Vector3d(-0.1, -0.2, 0), torso + Eigen::Vector3d(-0.2, -0.2, -0.05),
          torso + Eigen::Vector3d(0, 0.18, 0.25), hand + Eigen::Vector3d(0.15, 0, 0.05), hand};
}

struct Result {
  std::optional<msg::TaskOutcome> outcome;
  std::optional<msg::TaskOutcome> repeated;  // answer to the command sent again after the outcome
  int outcomes = 0;
  std::vector<double> last_waypoint;  // of the last trajectory before the outcome
  int trajectories = 0;
  int zero_stamped = 0;  // trajectories with header.stamp 0 ("start on receipt")
  double seconds = 0;
  std::string contacts;
};

// A person standing still with joints `joints`: 10 steps of 0.1 s, 3 cm sigma.
msg::HumanPrediction StandingPrediction(const msg::Time& stamp, const std::vector<Eigen::Vector3d>& joints) {
  msg::HumanPrediction m;
  m.header.stamp = stamp;
  m.header.frame_id = "world";
  m.observation_stamp = stamp;
  m.time_step = 0.1;
  m.num_steps = 10;
  m.joint_names = kJoints;
  msg::ActionPrediction a;
  a.action = "stand";
  a.probability = 1;
  for (int k = 0; k < 10; ++k) {
    for (const auto& j : joints) {
      msg::JointGaussian g;
      g.mean = {j.x(), j.y(), j.z()};
      g.covariance = {9e-4, 0, 0, 0, 9e-4, 0, 0, 0, 9e-4};
      a.joints.push_back(g);
    }
  }
  m.actions = {a};
  return m;
}

// The test's subscriptions: trajectories until the outcome, outcomes, and the
// simulator's true contacts.
void Observe(framework::Node& node, const bool& started, Result* r) {
  node.Subscribe(framework::topics::RobotTrajectory(),
                 std::function<void(const msg::JointTrajectory&, const dds::SampleInfo&)>(
                     [&started, r](const msg::JointTrajectory& t, const dds::SampleInfo&) {
                       if (started && !r->outcome) {
                         ++r->trajectories;
                         r->zero_stamped += t.header.stamp.sec == 0 && t.header.stamp.nanosec == 0;
                         if (!t.points.empty()) r->last_waypoint = t.points.back().positions;
                       }
                       EXPECT_EQ(t.joint_names.size(), 7u);
                     }));
  node.Subscribe(framework::topics::TaskOutcome(),
                 std::function<void(const msg::TaskOutcome&, const dds::SampleInfo&)>(
                     [r](const msg::TaskOutcome& m, const dds::SampleInfo&) {
                       ++r->outcomes;
                       (r->outcome ? r->repeated : r->outcome) = m;
                     }),
                 framework::SubscribeOptions{false});
  node.Subscribe(framework::topics::Diagnostics(),
                 std::function<void(const msg::DiagnosticArray&, const dds::SampleInfo&)>(
                     [r](const msg::DiagnosticArray& a, const dds::SampleInfo&) {
                       for (const auto& s : a.status) {
                         if (s.name != "robot_sim") continue;
                         for (const auto& kv : s.values) {
                           if (kv.key == "true_contacts") r->contacts = kv.value;
                         }
                       }
                     }));
}

// Where the hand (last link) of the Panda is at kGoal (m, W).
Eigen::Vector3d GoalHand() {
  auto model = collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
  collision::RobotData data(model);
  collision::CalcForwardKinematics(model, Eigen::Map<const Eigen::VectorXd>(kGoal.data(), 7), &data);
  return data.X_WL.back().translation();
}

// Task 42 to kGoal (then `retreat`, if any), 30 s time limit.
msg::TaskCommand StartCommand(const std::vector<double>& retreat) {
  return testing::JointGoalCommand(42, "reach_goal", kGoal, 30, retreat);
}

// Sends one task to the goal kGoal (with `retreat`, if any) while a person
// stands on the goal for `block_for_s`; `zero_stamp`: trajectories go out
// the joint_trajectory_controller way (trajopt.output.zero_stamp).
Result RunTask(double block_for_s, const std::vector<double>& retreat = {}, bool zero_stamp = false) {
  CellHarness services("trajopt-service", dds::Vendor::kCyclone,
                       61 + static_cast<int>(block_for_s * 10) + static_cast<int>(retreat.size()), "", /*with_intent=*/false);
  const int domain = services.domain();
  services.SetVendor("robot_sim", dds::Vendor::kFastDds);
  services.Start("robot_sim", {"--set", "robot_sim.permits.monitors=[test_cell]"});
  services.Start("trajopt", {"--set", "node.entitled_writers./iplan/task/command=[test_cell]", "--set",
                             "node.entitled_writers./iplan/human/prediction=[test_cell]", "--set",
                             std::string("trajopt.output.zero_stamp=") + (zero_stamp ? "true" : "false")});
  TestNode cell("test_cell", dds::Vendor::kCyclone, domain);
  TestNode stranger("stranger", dds::Vendor::kCyclone, domain);
  framework::Node& node = *cell.node;
  auto& cmd = node.Advertise(framework::topics::TaskCommand());
  auto& rogue_cmd = stranger.node->Advertise(framework::topics::TaskCommand());
  auto& permit = node.Advertise(framework::topics::SafetyPermit("test_cell"));
  auto& pred = node.Advertise(framework::topics::HumanPrediction());
  auto& truth = node.Advertise(framework::topics::HumanTruth());
  Result r;
  bool started = false;
  Observe(node, started, &r);
  // Both services up: the optimiser reads commands, and a hold trajectory flows.
  const auto up = Clock::now() + 30s;
  while (Clock::now() < up && (cmd.MatchedReaders() == 0 || pred.MatchedReaders() == 0 || truth.MatchedReaders() == 0)) {
    node.SpinOnce(20ms);
  }
  for (int i = 0; i < 20; ++i) node.SpinOnce(20ms);
  EXPECT_GT(cmd.MatchedReaders(), 0) << services.Logs("trajopt");

  const Eigen::Vector3d goal_hand = GoalHand();
  msg::TaskCommand c = StartCommand(retreat);
  const auto start = Clock::now();
  auto next = start;
  started = true;
  cmd.Write(c);
  // A stranger cancels the task: ignored (only test_cell is entitled).
  msg::TaskCommand cancel = c;
  cancel.command = msg::TaskCommand::CANCEL;
  rogue_cmd.Write(cancel);
  auto next_permit = start;
  while (!r.outcome && Clock::now() - start < 40s) {
    if (Clock::now() >= next_permit) {
      permit.Write(testing::TestPermit());
      next_permit += 50ms;
    }
    if (Clock::now() >= next) {
      const double t = std::chrono::duration<double>(Clock::now() - start).count();
      const Eigen::Vector3d hand = t < block_for_s ? goal_hand : Eigen::Vector3d(1.8, 0.8, 1.0);
      const auto joints = PersonWithHandAt(hand);
      const msg::Time stamp = msg::Now();
      pred.Write(StandingPrediction(stamp, joints));
      truth.Write(SkeletonMessage(stamp, kJoints, joints));
      next += 66ms;
    }
    node.SpinOnce(10ms);
  }
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  // The same command again, as a supervisor that missed the outcome sends it.
  c.header.stamp = msg::Now();
  cmd.Write(c);
  const auto diag_end = Clock::now() + 2s;
  while (Clock::now() < diag_end) node.SpinOnce(20ms);  // the simulator's next diagnostics, the repeat's answer
  services.Stop();
  return r;
}

TEST(TrajoptService, ReachesTheGoalPublishingEveryCycle) {
  const Result r = RunTask(0.0);
  ASSERT_TRUE(r.outcome.has_value()) << "no outcome";
  EXPECT_EQ(r.outcome->status, msg::TaskOutcome::SUCCEEDED) << r.outcome->reason;
  EXPECT_EQ(r.zero_stamped, 0);  // the shipped default: the time of waypoint 0
  EXPECT_EQ(r.outcome->task_id, 42u);
  EXPECT_EQ(r.outcome->num_waits, 0u);
  EXPECT_EQ(r.outcome->delay, 0.0);
  // A trajectory every 0.1 s cycle (allow for scheduling on 2 cores).
  EXPECT_GE(r.trajectories, static_cast<int>(0.7 * r.outcome->duration / 0.1)) << r.outcome->duration;
  EXPECT_GT(r.outcome->planning_time_p50, 0.0);
  EXPECT_EQ(r.contacts, "0");
  // The stranger's CANCEL changed nothing; the repeated command got the same outcome again.
  ASSERT_TRUE(r.repeated.has_value());
  EXPECT_EQ(r.outcomes, 2);
  EXPECT_EQ(r.repeated->task_id, 42u);
  EXPECT_EQ(r.repeated->status, msg::TaskOutcome::SUCCEEDED);
  EXPECT_EQ(r.repeated->duration, r.outcome->duration);
}

// robot_sim executes trajectories stamped 0 ("start on receipt", as for a
// joint_trajectory_controller) from their time of receipt: the task ends at
// the goal as with planned stamps.
TEST(TrajoptService, ReachesTheGoalWithZeroStampedTrajectories) {
  const Result r = RunTask(0.0, {}, /*zero_stamp=*/true);
  ASSERT_TRUE(r.outcome.has_value()) << "no outcome";
  EXPECT_EQ(r.outcome->status, msg::TaskOutcome::SUCCEEDED) << r.outcome->reason;
  EXPECT_GT(r.trajectories, 5);
  EXPECT_EQ(r.zero_stamped, r.trajectories);
  ASSERT_EQ(r.last_waypoint.size(), kGoal.size());
  for (std::size_t j = 0; j < kGoal.size(); ++j) EXPECT_NEAR(r.last_waypoint[j], kGoal[j], 0.01) << "joint " << j;
  EXPECT_LT(r.outcome->duration, 10.0);
  EXPECT_EQ(r.contacts, "0");
  std::cout << "zero-stamped: goal reached in " << r.outcome->duration << " s, " << r.trajectories << " trajectories\n";
}

TEST(TrajoptService, PersonOnTheGoalIsReportedAsWaitAndDelayNotContact) {
  const Result r = RunTask(3.0);
  ASSERT_TRUE(r.outcome.has_value()) << "no outcome";
  std::cout << "outcome: status " << int(r.outcome->status) << ", duration " << r.outcome->duration << " s, delay "
            << r.outcome->delay << " s, waits " << r.outcome->num_waits << ", planning p50/p99 "
            << r.outcome->planning_time_p50 << "/" << r.outcome->planning_time_p99 << " s, max bound "
            << r.outcome->max_collision_bound << "\n";
  EXPECT_EQ(r.outcome->status, msg::TaskOutcome::SUCCEEDED) << r.outcome->reason;
  EXPECT_GT(r.outcome->num_waits, 0u);
  // The person stands on the goal for 3 s; unobstructed the task takes about
  // 1.5 s (first test), so the robot must have waited well over a second.
  EXPECT_GT(r.outcome->delay, 1.0);
  EXPECT_GT(r.outcome->duration, 3.0);
  EXPECT_LT(r.outcome->max_collision_bound, 0.05);
  EXPECT_EQ(r.contacts, "0");
}

TEST(TrajoptService, TaskWithARetreatEndsThereAndAWrongRetreatIsRefused) {
  const std::vector<double> ready = {0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785};
  Result r = RunTask(0.0, ready);
  ASSERT_TRUE(r.outcome.has_value()) << "no outcome";
  EXPECT_EQ(r.outcome->status, msg::TaskOutcome::SUCCEEDED) << r.outcome->reason;
  ASSERT_EQ(r.last_waypoint.size(), ready.size());
  for (std::size_t j = 0; j < ready.size(); ++j) EXPECT_NEAR(r.last_waypoint[j], ready[j], 0.01) << "joint " << j;
  EXPECT_EQ(r.contacts, "0");

  r = RunTask(0.0, {0.0, -0.785, 0.0});
  ASSERT_TRUE(r.outcome.has_value()) << "no outcome";
  EXPECT_EQ(r.outcome->status, msg::TaskOutcome::FAILED);
  EXPECT_EQ(r.outcome->reason, "retreat has 3 joint positions, the robot 7");
}

}  // namespace
}  // namespace iplan::testing
