// RiskMonitor's layers for a person seen only as points (risk_monitor.h,
// point_risk.h): kept apart from the skeleton's layers in risk_monitor.cc.
#include <algorithm>

#include "risk_monitor.h"

namespace iplan::collision_risk {
namespace {
constexpr double kMinPointVariance = 1e-6;  // m^2, (1 mm)^2
}  // namespace

std::optional<std::string> RiskMonitor::UpdateHumanPoints(int64_t stamp_ns, double voxel_size,
                                                          const Eigen::Matrix3Xd& means,
                                                          const std::vector<Eigen::Matrix3d>& covariances) {
  if (!(voxel_size >= 0)) return std::string("human points: voxel_size is negative or not finite");
  const PointsParams& pp = params_.human_points;
  const double radius = std::max(pp.min_point_radius, 0.5 * voxel_size);
  // A floor of 1 mm standard deviation: noise-free points (a simulator's, a
  // zero covariance the boundary accepts as semi-definite) still have a
  // density; it changes the sensor's millimetre-to-centimetre noise by little.
  std::vector<Eigen::Matrix3d> floored(covariances);
  for (Eigen::Matrix3d& c : floored) c += kMinPointVariance * Eigen::Matrix3d::Identity();
  collision::GaussianPoints points;
  if (auto why = points.Set(means, floored, radius, pp.block_size)) return "human points: " + *why;
  points_ = std::move(points);
  points_stamp_ns_ = stamp_ns;
  return std::nullopt;
}

void RiskMonitor::EvaluateSeparationFromPoints(int64_t now_ns, RiskReport* out) {
  RiskReport& r = *out;
  const SsmParams& s = params_.ssm;
  Eigen::Matrix3Xd v_robot;
  RobotSphereVelocities(now_ns, &v_robot);
  collision::CalcForwardKinematics(robot_, state_->second, &data_);
  std::vector<double> radii;
  radii.reserve(robot_.spheres.size());
  for (const auto& sp : robot_.spheres) radii.push_back(sp.radius);
  const PointsSeparation p = EvaluatePointsSeparation(points_, data_.p_WS, radii, v_robot, s);
  if (!p.any) return;  // the camera sees nobody
  auto link = [&](int k) {
    return robot_.link_names[static_cast<std::size_t>(robot_.spheres[static_cast<std::size_t>(k)].link)];
  };
  r.min_separation = p.min_separation;
  r.separation_robot_link = link(p.closest_sphere);
  r.separation_human_segment = "points";
  r.binding_separation = p.binding_separation;
  r.protective_separation = p.protective_separation;
  r.human_speed = p.human_speed;
  r.robot_speed = p.robot_speed;
  r.separation_margin = p.margin();
  r.binding_robot_link = link(p.binding_sphere);
  r.binding_human_segment = "points";
}

// The executing trajectory at now + j time_step, j = 1 .. horizon /
// time_step, against the points where they are now.
void RiskMonitor::EvaluateBoundFromPoints(int64_t now_ns, RiskReport* out) {
  RiskReport& r = *out;
  if (points_.empty()) return;
  const PointsParams& pp = params_.human_points;
  r.time_step = pp.time_step;
  const int S = static_cast<int>(robot_.spheres.size());
  const int W = std::max(1, static_cast<int>(pp.horizon / pp.time_step + 1e-9));
  collision::RobotSpheresTrajectory traj;
  for (const auto& sp : robot_.spheres) {
    traj.radii.push_back(sp.radius);
    traj.links.push_back(sp.link);
  }
  traj.centres.resize(3, static_cast<Eigen::Index>(W) * S);
  for (int w = 0; w < W; ++w) {
    const double t = (w + 1) * pp.time_step;
    collision::CalcForwardKinematics(robot_, RobotConfigurationAt(now_ns + static_cast<int64_t>(t * 1e9)), &data_);
    traj.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = data_.p_WS;
    traj.steps.push_back(w);
    r.waypoint_times.push_back(t);
  }
  collision::EvaluatePointsBound(points_, traj, collision::PointsBoundParams{}, &bounds_);
  for (std::size_t w = 0; w < bounds_.size(); ++w) {
    const auto& b = bounds_[w];
    r.waypoint_bounds.push_back(std::clamp(b.bound, 0.0, 1.0));
    if (w == 0 || b.bound > r.max_bound) {
      r.max_bound = std::clamp(b.bound, 0.0, 1.0);
      r.max_waypoint = static_cast<int>(w);
      r.max_time = r.waypoint_times[w];
      r.max_robot_link = b.robot_link >= 0 ? robot_.link_names[static_cast<std::size_t>(b.robot_link)] : "";
      r.max_human_segment = "points";
      r.max_action = "as seen";
    }
  }
}

}  // namespace iplan::collision_risk
