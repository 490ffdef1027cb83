// A person walking at a robot that stands still (issue 25, "yield"):
// iplan-trajopt, iplan-collision-risk and iplan-robot-sim as separate
// processes on loopback DDS (the optimiser on Fast DDS, the others on
// Cyclone). The person's skeleton and the true prediction of their walk come
// from the test, through participants named as the perception and intent
// services (the topics' entitled writers); the supervisor's permit from the
// test's own participant. The robot has no task: the optimiser, predicting
// the separation monitor's rule, must move the arm out of the hand's way
// (instead of standing there to be stopped, or touched), and the robot must
// never touch the person.
#include <signal.h>

#include <algorithm>
#include <cstdlib>
#include <limits>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "iplan/collision/human_model.h"
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

const std::vector<double>& kReady = kPandaReady;

// The person's joints (the body model's order) with the right hand at `hand`,
// standing behind it (+x), facing the robot.
std::vector<Eigen::Vector3d> PersonAt(const Eigen::Vector3d& hand) {
  const Eigen::Vector3d torso = hand + Eigen::Vector3d(0.35, 0.1, 0.1);
  return {torso + Eigen::Vector3d(0, 0, 0.48),     torso + Eigen::Vector3d(0, 0, 0.3),
          torso,                                   torso + Eigen::Vector3d(0, -0.18, 0.25),
          torso + Eigen::Vector3d(-0.1, -0.2, 0),  torso + Eigen::Vector3d(-0.2, -0.2, -0.05),
          torso + Eigen::Vector3d(0, 0.18, 0.25),  hand + Eigen::Vector3d(0.15, 0, 0.05),
          hand};
}

// The hand's offset along x from the resting tool (m) at `s` s into the
// walk: 0.70 m, coming in at 0.3 m/s to 0.20 m (inside the protective
// separation of a robot at rest, 0.17 m + 0.4 s x the hand's speed, for the
// tool's sphere), held there until 4 s, then back to 0.9 m.
double Offset(double s) { return s < 4.0 ? std::max(0.20, 0.70 - 0.3 * std::max(0.0, s)) : 0.90; }

// The skeleton with the hand at `hand`, and the true future of the walk from
// `s` s on (10 steps of 0.1 s, 3 cm sigma) as the prediction.
msg::HumanSkeleton Skeleton(const collision::HumanBodyModel& body, const msg::Time& stamp, const Eigen::Vector3d& hand) {
  msg::HumanSkeleton sk;
  sk.header.stamp = stamp;
  sk.header.frame_id = "world";
  sk.body_id = 1;
  sk.confidence = 1;
  const auto joints = PersonAt(hand);
  for (std::size_t j = 0; j < joints.size(); ++j) {
    msg::HumanJoint hj;
    hj.name = body.params().joints[j];
    hj.position = {joints[j].x(), joints[j].y(), joints[j].z()};
    hj.confidence = 1;
    sk.joints.push_back(hj);
  }
  return sk;
}

msg::HumanPrediction Prediction(const collision::HumanBodyModel& body, const msg::Time& stamp,
                                const Eigen::Vector3d& rest_tool, double s) {
  msg::HumanPrediction pr;
  pr.header.stamp = stamp;
  pr.header.frame_id = "world";
  pr.observation_stamp = stamp;
  pr.body_id = 1;
  pr.time_step = 0.1;
  pr.num_steps = 10;
  pr.joint_names = body.params().joints;
  msg::ActionPrediction a;
  a.action = "walk";
  a.probability = 1;
  for (int k = 1; k <= 10; ++k) {
    for (const auto& j : PersonAt(rest_tool + Eigen::Vector3d(Offset(s + 0.1 * k), 0, 0))) {
      msg::JointGaussian g;
      g.mean = {j.x(), j.y(), j.z()};
      g.covariance = {9e-4, 0, 0, 0, 9e-4, 0, 0, 0, 9e-4};
      a.joints.push_back(g);
    }
  }
  pr.actions = {a};
  return pr;
}

// What the executed joint states (stamped by the test's clock) show: how far
// the tool went from where it rested, how near the tool's centre came to the
// hand while the hand was in (before 4 s), and the smallest surface distance
// between robot and person.
struct Motion {
  double moved = 0, closest = std::numeric_limits<double>::infinity(), separation = closest;
};
Motion Measure(const collision::RobotModel& robot, const collision::HumanBodyModel& body, const Eigen::Vector3d& rest_tool,
               Clock::time_point walk, const std::vector<std::pair<Clock::time_point, std::vector<double>>>& states) {
  Motion m;
  collision::RobotData data(robot);
  const Eigen::Index tool = static_cast<Eigen::Index>(robot.spheres.size()) - 1;
  for (const auto& [at, q] : states) {
    const double s = std::chrono::duration<double>(at - walk).count();
    collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(q.data(), 7), &data);
    const Eigen::Vector3d hand = rest_tool + Eigen::Vector3d(Offset(s), 0, 0);
    m.moved = std::max(m.moved, (data.p_WS.col(tool) - rest_tool).norm());
    if (s < 4.0) m.closest = std::min(m.closest, (data.p_WS.col(tool) - hand).norm());
    const auto joints = PersonAt(hand);
    Eigen::Matrix3Xd p_WJ(3, static_cast<Eigen::Index>(joints.size()));
    for (std::size_t j = 0; j < joints.size(); ++j) p_WJ.col(static_cast<Eigen::Index>(j)) = joints[j];
    for (int h = 0; h < body.num_spheres(); ++h) {
      for (std::size_t k = 0; k < robot.spheres.size(); ++k) {
        m.separation = std::min(m.separation, (data.p_WS.col(static_cast<Eigen::Index>(k)) - body.SphereCentre(h, p_WJ)).norm() -
                                                  robot.spheres[k].radius - body.spheres()[static_cast<std::size_t>(h)].radius);
      }
    }
  }
  return m;
}

// What the test sees of the cell while the person walks: the executed joint
// states (stamped by the test's clock) and the collision-risk verdicts.
struct Observed {
  explicit Observed(framework::Node& node) {
    node.Subscribe(framework::topics::JointStates(),
                   std::function<void(const msg::JointState&, const dds::SampleInfo&)>(
                       [this](const msg::JointState& m, const dds::SampleInfo&) {
                         if (walking) states.emplace_back(Clock::now(), m.position);
                       }));
    node.Subscribe(framework::topics::CollisionRisk(),
                   std::function<void(const msg::CollisionRisk&, const dds::SampleInfo&)>(
                       [this](const msg::CollisionRisk& m, const dds::SampleInfo&) {
                         if (walking && m.verdict != last_verdict) {
                           stops += m.verdict == msg::CollisionRisk::PROTECTIVE_STOP;
                           slow_downs += m.verdict == msg::CollisionRisk::SLOW_DOWN;
                         }
                         last_verdict = m.verdict;
                       }));
  }
  bool walking = false;
  std::vector<std::pair<Clock::time_point, std::vector<double>>> states;
  int stops = 0, slow_downs = 0;
  uint8_t last_verdict = msg::CollisionRisk::OK;
};

TEST(Yield, ARobotAtRestMovesOutOfTheWayOfAPersonComingAtIt) {
  const collision::RobotModel robot =
      collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
  const collision::HumanBodyModel body(collision::HumanBodyParams::DefaultUpperBody());
  collision::RobotData data(robot);
  collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(kReady.data(), 7), &data);
  const Eigen::Index tool = static_cast<Eigen::Index>(robot.spheres.size()) - 1;
  const Eigen::Vector3d rest_tool = data.p_WS.col(tool);

  CellHarness services("yield", dds::Vendor::kCyclone, 95, "", /*with_intent=*/false);
  const int domain = services.domain();
  services.Start("robot_sim", {"--set", "robot_sim.permits.monitors=[test_cell,iplan-collision_risk]"});
  services.Start("collision_risk");
  services.SetVendor("trajopt", dds::Vendor::kFastDds);
  services.Start("trajopt");
  TestNode cell("test_cell", dds::Vendor::kCyclone, domain);
  TestNode perception("iplan-perception", dds::Vendor::kCyclone, domain);
  TestNode intent("iplan-intent", dds::Vendor::kCyclone, domain);
  framework::Node& node = *cell.node;
  auto& permit = node.Advertise(framework::topics::SafetyPermit("test_cell"));
  auto& skeleton = perception.node->Advertise(framework::topics::HumanSkeleton());
  auto& prediction = intent.node->Advertise(framework::topics::HumanPrediction());
  Observed seen(node);
  const auto up = Clock::now() + 30s;
  while (Clock::now() < up && (prediction.MatchedReaders() < 2 || skeleton.MatchedReaders() == 0 ||
                               permit.MatchedReaders() == 0)) {
    node.SpinOnce(20ms);
  }
  ASSERT_GE(prediction.MatchedReaders(), 2) << services.Logs("trajopt") << services.Logs("collision_risk");

  // The person's frames at 30 Hz, each with the true future of the walk (10
  // steps of 0.1 s) as the prediction; the supervisor's permit at 20 Hz.
  const auto begin = Clock::now();
  const auto walk = begin + 2s;  // the cell settles with the person far away
  auto next_frame = begin, next_permit = begin;
  while (Clock::now() - walk < 6s) {
    const auto now = Clock::now();
    const double s = std::chrono::duration<double>(now - walk).count();
    seen.walking = s >= 0;
    if (now >= next_permit) {
      permit.Write(testing::TestPermit());
      next_permit += 50ms;
    }
    if (now >= next_frame) {
      const msg::Time stamp = msg::Now();
      skeleton.Write(Skeleton(body, stamp, rest_tool + Eigen::Vector3d(Offset(s), 0, 0)));
      prediction.Write(Prediction(body, stamp, rest_tool, s));
      next_frame += 33ms;
    }
    node.SpinOnce(2ms);
  }
  services.Stop();

  ASSERT_GT(seen.states.size(), 100u);
  const Motion m = Measure(robot, body, rest_tool, walk, seen.states);
  const double moved = m.moved, closest = m.closest, separation = m.separation;
  std::cout << "tool moved up to " << moved << " m from rest; tool centre to hand at least " << closest
            << " m (standing still: 0.20 m); smallest robot-person separation " << separation
            << " m; collision-risk verdicts while walking: " << seen.stops << " protective stop(s), " << seen.slow_downs
            << " slow-down(s)\n";
  EXPECT_GT(moved, 0.08) << "the arm did not get out of the way\n" << services.Logs("trajopt");
  EXPECT_GT(closest, 0.20 + 0.05) << services.Logs("trajopt");
  EXPECT_GT(separation, 0.0) << "the person touched the robot";
}

}  // namespace
}  // namespace iplan::testing
