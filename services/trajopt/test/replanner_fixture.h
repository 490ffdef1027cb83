// The replanning loop's test fixture: the cell's Panda planner, the upper
// body, an ideal robot that follows every published plan (Run), and a
// person standing with a hand at a given place (PersonAt). Shared by
// replanner_test.cc (tasks) and replanner_standby_test.cc (no task).
#pragma once

#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "services/trajopt/core/replanner.h"
#include "iplan/planning/planner_params.h"

namespace iplan::trajopt {

inline constexpr int64_t kSec = 1000000000;
inline const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config/";

class ReplannerTest : public ::testing::Test {
 public:
  // The Panda's ready pose and a goal (rad); also used by the points tests.
  static Eigen::VectorXd Ready() {
    Eigen::VectorXd q(7);
    q << 0, -0.785, 0, -2.356, 0, 1.571, 0.785;
    return q;
  }
  static Eigen::VectorXd Goal() {
    Eigen::VectorXd q(7);
    q << 0.6, -0.2, 0.0, -2.0, 0.0, 1.9, 0.8;
    return q;
  }
  // A planner with the cell's replanning settings (predict_ssm on).
  static std::unique_ptr<planning::Planner> PredictingPlanner() {
    const planning::PlannerParams pp = planning::LoadPlannerParams(kConfig + "planner_replanning.yaml");
    EXPECT_TRUE(pp.predict_ssm);
    return std::make_unique<planning::Planner>(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                                               collision::LoadSceneParams(kConfig + "scenes/cell.yaml"), pp);
  }
  // The tool sphere's centre (m, world) at the ready pose.
  static Eigen::Vector3d ToolAtReady(const collision::RobotModel& robot) {
    collision::RobotData d(robot);
    collision::CalcForwardKinematics(robot, Ready(), &d);
    return d.p_WS.col(static_cast<int>(robot.spheres.size()) - 1);
  }
  // A one-action prediction of `body` from t0: `num_steps` steps of 0.1 s,
  // the joints (body order, m, world) of step k from joints_at(k), each with
  // a 3 cm isotropic standard deviation.
  static collision::JointMixture Mixture(const collision::HumanBodyModel& body, int64_t t0, int num_steps,
                                         const std::function<std::vector<Eigen::Vector3d>(int)>& joints_at) {
    collision::JointMixture m;
    m.t0_ns = t0;
    m.time_step = 0.1;
    m.num_steps = num_steps;
    m.joint_names = body.params().joints;
    m.actions = {"stand"};
    m.probabilities = {1.0};
    m.means.resize(1);
    m.covariances.resize(1);
    for (int k = 0; k < m.num_steps; ++k) {
      for (const auto& j : joints_at(k)) {
        m.means[0].push_back(j);
        m.covariances[0].push_back(0.03 * 0.03 * Eigen::Matrix3d::Identity());
      }
    }
    return m;
  }
  // The upper body standing with its torso at `torso` and its right hand at
  // `hand` (m, world), body joint order.
  static std::vector<Eigen::Vector3d> Body(const Eigen::Vector3d& torso, const Eigen::Vector3d& hand,
                                           const Eigen::Vector3d& elbow_r) {
    return {torso + Eigen::Vector3d(0, 0, 0.48), torso + Eigen::Vector3d(0, 0, 0.3), torso,
            torso + Eigen::Vector3d(0, -0.18, 0.25), torso + Eigen::Vector3d(-0.1, -0.2, 0), torso + Eigen::Vector3d(-0.2, -0.2, -0.05),
            torso + Eigen::Vector3d(0, 0.18, 0.25), elbow_r, hand};
  }
 protected:
  ReplannerTest()
      : planner_(collision::LoadRobotModelFromYaml(kConfig + "robots/panda.yaml"),
                 collision::LoadSceneParams(kConfig + "scenes/cell.yaml"),
                 planning::LoadPlannerParams(kConfig + "planner.yaml")),
        body_(collision::HumanBodyParams::DefaultUpperBody()),
        replanner_(planner_, body_, ReplannerParams{}) {}

  // Position of a published plan at time t (linear interpolation).
  static Eigen::VectorXd At(const CycleResult& c, int64_t t) {
    const double s = std::max(0.0, (t - c.start_ns) * 1e-9 / c.dt);
    const int i = std::min(static_cast<int>(s), static_cast<int>(c.positions.cols()) - 1);
    const int j = std::min(i + 1, static_cast<int>(c.positions.cols()) - 1);
    const double u = std::min(1.0, s - i);
    return (1 - u) * c.positions.col(i) + u * c.positions.col(j);
  }
  void SetState(int64_t t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    ASSERT_EQ(replanner_.UpdateRobotState(t, replanner_.joint_names(),
                                          std::vector<double>(q.data(), q.data() + q.size()),
                                          std::vector<double>(qd.data(), qd.data() + qd.size())),
              std::nullopt);
  }
  // A person whose right hand is at `hand` (m, world), standing behind it.
  collision::JointMixture PersonAt(int64_t t0, const Eigen::Vector3d& hand) {
    const Eigen::Vector3d torso = hand + Eigen::Vector3d(0.35, 0.1, 0.1);
    return Mixture(body_, t0, 10, [&](int) { return Body(torso, hand, hand + Eigen::Vector3d(0.15, 0, 0.05)); });
  }
  // Runs cycles every 0.1 s with an ideal robot until an outcome or `max_cycles`.
  std::optional<TaskOutcome> Run(int64_t* t, int max_cycles, const std::function<void(int64_t)>& each = nullptr) {
    std::optional<CycleResult> last;
    for (int k = 0; k < max_cycles; ++k) {
      if (each) each(*t);
      CycleResult c = replanner_.Cycle(*t);
      statuses_.push_back(c.status);
      if (c.outcome) return c.outcome;
      if (c.publish) {
        if (last && last->positions.cols() > 1) {
          // The new plan starts where the executing one is at that time.
          EXPECT_LT((At(*last, c.start_ns) - c.positions.col(0)).cwiseAbs().maxCoeff(), 1e-6) << "cycle " << k;
        }
        last = c;
      }
      const int64_t next = *t + kSec / 10;
      const Eigen::VectorXd q = last ? At(*last, next) : Ready();
      const Eigen::VectorXd q2 = last ? At(*last, next + kSec / 100) : Ready();
      SetState(next, q, (q2 - q) / 0.01);
      visited_.push_back(q);
      *t = next;
    }
    return std::nullopt;
  }

  planning::Planner planner_;
  collision::HumanBodyModel body_;
  Replanner replanner_;
  std::vector<std::string> statuses_;       // of every cycle Run() made
  std::vector<Eigen::VectorXd> visited_;    // the ideal robot's states in Run()
};

}  // namespace iplan::trajopt
