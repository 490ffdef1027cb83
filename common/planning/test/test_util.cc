#include "test_util.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace iplan::planning::testing {

collision::RobotModel LoadPanda() {
  return collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
}

collision::SceneParams LoadCell() {
  return collision::LoadSceneParams(std::string(IPLAN_SOURCE_DIR) + "/config/scenes/cell.yaml");
}

Eigen::VectorXd Ready() {
  Eigen::VectorXd q(7);
  q << 0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8;
  return q;
}

Eigen::Quaterniond DownOrientation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
}

std::optional<PlanningRequest> AcrossTheTable(const Planner& planner) {
  const IkResult s = planner.SolveIk({0.45, -0.35, 0.30}, DownOrientation(0.0), Ready(), 1);
  const IkResult g = planner.SolveIk({0.45, 0.15, 0.30}, DownOrientation(0.0), Ready(), 1);
  if (!s.success || !g.success) return std::nullopt;
  PlanningRequest req;
  req.start_q = s.q;
  req.goal = Goal::Joint(g.q);
  return req;
}

std::vector<NamedPose> TableTopPoses() {
  return {
      {"table_centre", {0.50, 0.00, 0.30}},  {"table_left", {0.42, 0.15, 0.30}},
      {"table_right", {0.45, -0.30, 0.30}},  {"table_far", {0.65, -0.10, 0.32}},
      {"table_near", {0.35, 0.05, 0.35}},    {"shelf_right", {0.35, -0.40, 0.65}},
      {"shelf_high", {0.45, 0.00, 0.70}},    {"shelf_left", {0.30, 0.35, 0.60}},
      {"bin_above", {0.55, 0.45, 0.48}},     {"bin_edge", {0.45, 0.40, 0.45}},
  };
}

collision::HumanPrediction MakeReachingPrediction(const collision::HumanBodyModel& body,
                                                  const std::vector<Eigen::Vector3d>& targets,
                                                  int num_steps, double sigma0, double sigma1,
                                                  Eigen::Vector3d off) {
  const int na = static_cast<int>(targets.size());
  collision::HumanPrediction pred = body.MakePrediction(na, num_steps);
  // Skeleton of a person facing -x, standing at x = 1.15 (W, m).
  const auto& names = body.params().joints;
  auto J = [&](const std::string& n) {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == n) return static_cast<int>(i);
    // A silent -1 once left the arms at the origin (the robot base) after the
    // body model's joint names changed; fail loudly instead.
    throw std::invalid_argument("MakeReachingPrediction: body model has no joint '" + n + "'");
  };
  Eigen::Matrix3Xd rest(3, body.num_joints());
  rest.setZero();
  const std::pair<const char*, Eigen::Vector3d> pose[] = {
      {"head", {1.15, 0.0, 0.85}},          {"neck", {1.15, 0.0, 0.60}},
      {"torso", {1.15, 0.0, 0.20}},         {"shoulder_l", {1.15, 0.20, 0.55}},
      {"elbow_l", {1.10, 0.25, 0.30}},   {"hand_l", {1.00, 0.25, 0.15}},
      {"shoulder_r", {1.15, -0.20, 0.55}}, {"elbow_r", {1.05, -0.25, 0.32}},
      {"hand_r", {0.95, -0.25, 0.20}}};
  for (const auto& [n, p] : pose) {
    rest.col(J(n)) = p + off;
  }
  double wsum = 0.0;
  for (int c = 0; c < na; ++c) wsum += std::pow(0.6, c);
  std::vector<Eigen::Matrix3d> covs(body.num_joints());
  for (int c = 0; c < na; ++c) {
    pred.set_action_probability(c, std::pow(0.6, c) / wsum);
    for (int s = 0; s < num_steps; ++s) {
      const double u = num_steps > 1 ? static_cast<double>(s) / (num_steps - 1) : 1.0;
      Eigen::Matrix3Xd m = rest;
      const int hand = J("hand_r"), elbow = J("elbow_r"), sh = J("shoulder_r");
      m.col(hand) = (1.0 - u) * rest.col(hand) + u * targets[c];
      m.col(elbow) = 0.5 * (m.col(sh) + m.col(hand)) + Eigen::Vector3d(0.0, 0.0, -0.05);
      const double sd = sigma0 + (sigma1 - sigma0) * u;
      for (auto& cv : covs) cv = sd * sd * Eigen::Matrix3d::Identity();
      body.FillPrediction(m, covs, c, s, &pred);
    }
  }
  pred.UpdateSummaries();
  return pred;
}

}  // namespace iplan::planning::testing
