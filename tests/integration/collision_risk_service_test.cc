// iplan-collision-risk as a separate process (Fast DDS); this process (Cyclone
// DDS) plays the robot (joint states, a held trajectory) and a scripted
// person (skeletons and constant-velocity predictions). A person walking
// towards the robot is flagged PROTECTIVE_STOP before the ISO/TS 15066
// separation is violated; a person who stays away is OK throughout.
#include <signal.h>

#include <cmath>
#include <iostream>

#include <Eigen/Core>

#include <gtest/gtest.h>

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
const std::vector<std::string>& kRobotJoints = kPandaJoints;
const std::vector<double>& kReady = kPandaReady;

std::vector<Eigen::Vector3d> Person(const Eigen::Vector3d& torso) {
  return {torso + Eigen::Vector3d(0, 0, 0.48), torso + Eigen::Vector3d(0, 0, 0.30), torso,
          torso + Eigen::Vector3d(0, -0.18, 0.25), torso + Eigen::Vector3d(-0.1, -0.2, 0.0),
          torso + Eigen::Vector3d(-0.25, -0.2, -0.05), torso + Eigen::Vector3d(0, 0.18, 0.25),
          torso + Eigen::Vector3d(-0.1, 0.2, 0.05), torso + Eigen::Vector3d(-0.3, 0.1, 0.0)};
}

struct Scenario {
  Eigen::Vector3d start;
  Eigen::Vector3d velocity;  // m/s
  double duration;           // s
};

// A one-action constant-velocity prediction from `torso`, 15 steps of 1/15 s,
// sigma growing from 3 cm by 5 cm per second.
msg::HumanPrediction PredictionFrom(const msg::Time& stamp, const Eigen::Vector3d& torso, const Eigen::Vector3d& velocity) {
  msg::HumanPrediction m;
  m.header.stamp = stamp;
  m.observation_stamp = stamp;
  m.header.frame_id = "world";
  m.body_id = 1;
  m.time_step = 1.0 / 15;
  m.num_steps = 15;
  m.joint_names = kJoints;
  msg::ActionPrediction a;
  a.action = "walk_to_robot";
  a.probability = 1;
  for (int k = 0; k < 15; ++k) {
    const double tau = (k + 1) / 15.0;
    const double var = std::pow(0.03 + 0.05 * tau, 2);
    for (const auto& j : Person(torso + velocity * tau)) {
      msg::JointGaussian g;
      g.mean = {j.x(), j.y(), j.z()};
      g.covariance = {var, 0, 0, 0, var, 0, 0, 0, var};
      a.joints.push_back(g);
    }
  }
  m.actions = {a};
  return m;
}

std::vector<msg::CollisionRisk> RunScenario(const Scenario& sc) {
  CellHarness services("collision-risk-service", dds::Vendor::kCyclone, 41 + static_cast<int>(sc.velocity.norm() * 10), "",
                       /*with_intent=*/false);
  const int domain = services.domain();
  // The test plays robot, trajectory optimiser, perception and intent from
  // one participant: entitle it to write what trajopt and intent write.
  services.SetVendor("collision_risk", dds::Vendor::kFastDds);
  services.Start("collision_risk", {"--set", "node.entitled_writers./iplan/robot/trajectory=[scripted_cell]", "--set",
                                    "node.entitled_writers./iplan/human/prediction=[scripted_cell]"});
  TestNode cell("scripted_cell", dds::Vendor::kCyclone, domain);
  framework::Node& node = *cell.node;
  auto& js = node.Advertise(framework::topics::JointStates());
  auto& traj = node.Advertise(framework::topics::RobotTrajectory());
  auto& skel = node.Advertise(framework::topics::HumanSkeleton());
  auto& pred = node.Advertise(framework::topics::HumanPrediction());
  std::vector<msg::CollisionRisk> risks;
  bool started = false;
  node.Subscribe(framework::topics::CollisionRisk(),
                 std::function<void(const msg::CollisionRisk&, const dds::SampleInfo&)>(
                     [&](const msg::CollisionRisk& r, const dds::SampleInfo&) {
                       if (started) risks.push_back(r);
                     }));
  // Wait for the service to be up: every one of its readers matched ours,
  // so no early sample is lost to discovery on a loaded machine.
  const auto matched = [&] {
    return js.MatchedReaders() > 0 && traj.MatchedReaders() > 0 && skel.MatchedReaders() > 0 && pred.MatchedReaders() > 0;
  };
  const auto up = Clock::now() + 20s;
  while (Clock::now() < up && !matched()) node.SpinOnce(20ms);
  EXPECT_TRUE(matched()) << services.Logs("collision_risk");

  msg::JointTrajectory hold;
  hold.joint_names = kRobotJoints;
  msg::JointTrajectoryPoint pt;
  pt.positions = kReady;
  hold.points = {pt};
  const auto start = Clock::now();
  auto next_js = start, next_skel = start, next_pred = start;
  started = true;
  while (Clock::now() - start < std::chrono::duration<double>(sc.duration)) {
    const auto now = Clock::now();
    const double t = std::chrono::duration<double>(now - start).count();
    const msg::Time stamp = msg::Now();
    const Eigen::Vector3d torso = sc.start + sc.velocity * t;
    if (now >= next_js) {
      msg::JointState s;
      s.header.stamp = stamp;
      s.name = kRobotJoints;
      s.position = kReady;
      js.Write(s);
      hold.header.stamp = stamp;
      traj.Write(hold);
      next_js += 20ms;
    }
    if (now >= next_skel) {
      skel.Write(SkeletonMessage(stamp, kJoints, Person(torso), 1));
      next_skel += 33ms;
    }
    if (now >= next_pred) {
      pred.Write(PredictionFrom(stamp, torso, sc.velocity));
      next_pred += 66ms;
    }
    node.SpinOnce(5ms);
  }
  services.Stop();
  return risks;
}

TEST(CollisionRiskService, ApproachingPersonStopsTheRobotBeforeSeparationIsViolated) {
  // Torso from 2.2 m to 0.4 m in front of the robot base at 0.6 m/s.
  const auto risks = RunScenario({{2.2, 0.0, 0.55}, {-0.6, 0, 0}, 3.0});
  ASSERT_GT(risks.size(), 30u);
  int first_stop = -1, first_violation = -1;
  for (std::size_t i = 0; i < risks.size(); ++i) {
    const auto& r = risks[i];
    // Start-up: no robot state or no person tracked yet (both stop, by design).
    if (r.reason == "no robot state yet" || r.reason.rfind("no person tracked yet", 0) == 0) continue;
    if (first_stop < 0 && r.verdict == msg::CollisionRisk::PROTECTIVE_STOP) first_stop = static_cast<int>(i);
    if (first_violation < 0 && r.separation_margin < 0) first_violation = static_cast<int>(i);
  }
  ASSERT_GE(first_stop, 0) << "never stopped";
  ASSERT_GE(first_violation, 0) << "the scripted person should end up inside S_p";
  const auto& stop = risks[static_cast<std::size_t>(first_stop)];
  std::cout << "first protective stop: separation " << stop.min_separation << " m, S_p "
            << stop.protective_separation << " m, bound " << stop.max_bound << " at +" << stop.max_time
            << " s: " << stop.reason << "\n";
  EXPECT_LT(first_stop, first_violation);
  EXPECT_GT(stop.separation_margin, 0.0);
  EXPECT_NE(stop.reason.find("collision bound"), std::string::npos) << stop.reason;
  EXPECT_EQ(stop.max_action, "walk_to_robot");
  // Once the separation is violated, every later verdict is a stop.
  for (std::size_t i = static_cast<std::size_t>(first_violation); i < risks.size(); ++i) {
    EXPECT_EQ(risks[i].verdict, msg::CollisionRisk::PROTECTIVE_STOP) << risks[i].reason;
  }
}

TEST(CollisionRiskService, PersonWhoStaysAwayIsOk) {
  const auto risks = RunScenario({{2.0, 0.3, 0.55}, {0, 0, 0}, 2.0});
  int evaluated = 0;
  for (const auto& r : risks) {
    if (r.reason == "no robot state yet" || r.prediction_stamp.sec == 0) continue;
    // The first prediction may come before the first skeleton (the topics'
    // first samples arrive in any order); once a verdict has counted, the
    // person must stay tracked.
    if (evaluated == 0 && r.reason.rfind("no person tracked yet", 0) == 0) continue;
    ++evaluated;
    EXPECT_EQ(r.verdict, msg::CollisionRisk::OK) << r.reason;
    EXPECT_LT(r.max_bound, 0.05 * 0.5);
    EXPECT_GT(r.separation_margin, 0.0);
    EXPECT_GE(r.min_separation - r.protective_separation, r.separation_margin - 1e-9);
    EXPECT_GE(r.waypoint_bounds.size(), 13u);  // the future steps of a 15-step prediction
    EXPECT_LT(r.max_waypoint, r.waypoint_bounds.size());
  }
  std::cout << evaluated << " evaluations of the prediction in 2 s\n";
  EXPECT_GT(evaluated, 15);
}

}  // namespace
}  // namespace iplan::testing
