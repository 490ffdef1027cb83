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
  cell::HumanPoints p;
  p.stamp_ns = stamp_ns;
  p.voxel_size = voxel_size;
  p.means = means;
  p.covariances = covariances;
  return UpdateHumanPoints(std::move(p));
}

std::optional<std::string> RiskMonitor::UpdateHumanPoints(cell::HumanPoints seen) {
  if (!(seen.voxel_size >= 0)) return std::string("human points: voxel_size is negative or not finite");
  if (auto why = seen.Check()) return "human points: " + *why;
  const PointsParams& pp = params_.human_points;
  if (!pp.tracked_speeds) {  // every point untracked: the ISO default speed, where seen
    seen.motion_of.clear();
    seen.motions.clear();
  }
  const double radius = std::max(pp.min_point_radius, 0.5 * seen.voxel_size);
  // A floor of 1 mm standard deviation: noise-free points (a simulator's, a
  // zero covariance the boundary accepts as semi-definite) still have a
  // density; it changes the sensor's millimetre-to-centimetre noise by little.
  for (Eigen::Matrix3d& c : seen.covariances) c += kMinPointVariance * Eigen::Matrix3d::Identity();
  collision::GaussianPoints points;
  if (auto why = points.Set(seen.means, seen.covariances, radius, pp.block_size)) return "human points: " + *why;
  points_ = std::move(points);
  points_stamp_ns_ = seen.stamp_ns;
  seen_points_ = std::move(seen);
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
  const PointsSeparation p =
      EvaluatePointsSeparation(points_, seen_points_, data_.p_WS, radii, v_robot, s, params_.human_points.speed_sigmas);
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
  r.retreating = p.retreating;
  r.stop_scale = p.stop_scale;
  if (s.speed_reduction && p.slow_scale < 1.0) r.speed_scale = std::max(s.min_speed_scale, p.slow_scale);
  r.binding_robot_link = link(p.binding_sphere);
  r.binding_human_segment = "points";
}

// The executing trajectory at now + j time_step, j = 1 .. horizon /
// time_step, against the points predicted to that time: a tracked point at
// its velocity (for at most motion_horizon) with its covariance grown by
// t^2 C (t from the cloud's stamp), the others where they were seen.
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
  traj.centres.resize(3, S);
  traj.steps = {0};
  const bool moving = !seen_points_.motions.empty();
  const int n = points_.size();
  Eigen::Matrix3Xd means(3, n);
  std::vector<Eigen::Matrix3d> covariances(static_cast<std::size_t>(n));
  collision::GaussianPoints predicted;
  std::vector<collision::WaypointBound> one;
  bounds_.resize(static_cast<std::size_t>(W));
  // The bound retreat's alternative (CompareWithStandingStill): the robot
  // held where it stands, within the stop horizon, unless the trajectory
  // holds it there anyway.
  std::vector<int64_t> times(static_cast<std::size_t>(W));
  for (int w = 0; w < W; ++w) times[static_cast<std::size_t>(w)] = now_ns + static_cast<int64_t>((w + 1) * pp.time_step * 1e9);
  const bool compare = MovesWithinStopHorizon(now_ns, times);
  Eigen::Matrix3Xd held;
  if (compare) {
    collision::CalcForwardKinematics(robot_, state_->second, &data_);
    held = data_.p_WS;
    r.hold_bound = 0;
    r.horizon_bound = 0;
  }
  for (int w = 0; w < W; ++w) {
    const double t = (w + 1) * pp.time_step;
    collision::CalcForwardKinematics(robot_, RobotConfigurationAt(times[static_cast<std::size_t>(w)]), &data_);
    traj.centres = data_.p_WS;
    r.waypoint_times.push_back(t);
    const collision::GaussianPoints* at = &points_;
    if (moving) {
      const double age = std::max(0.0, (now_ns - points_stamp_ns_) * 1e-9 + t);  // s since the points were seen
      for (int i = 0; i < n; ++i) {
        means.col(i) = seen_points_.means.col(i);
        covariances[static_cast<std::size_t>(i)] = seen_points_.covariances[static_cast<std::size_t>(i)];  // floored
        if (const cell::PointMotion* m = seen_points_.MotionOf(i)) {
          means.col(i) += std::min(age, pp.motion_horizon) * m->velocity;
          covariances[static_cast<std::size_t>(i)] += age * age * m->covariance;
        }
      }
      // A covariance grown by a semi-definite one stays positive definite:
      // Set does not refuse it (were it to, the points as seen are used).
      if (!predicted.Set(means, covariances, points_.radius(), pp.block_size)) at = &predicted;
    }
    collision::EvaluatePointsBound(*at, traj, collision::PointsBoundParams{}, &one);
    bounds_[static_cast<std::size_t>(w)] = one.front();
    if (compare && t <= params_.stop_horizon) {
      r.horizon_bound = std::max(r.horizon_bound, std::clamp(one.front().bound, 0.0, 1.0));
      traj.centres = held;
      collision::EvaluatePointsBound(*at, traj, collision::PointsBoundParams{}, &one);
      r.hold_bound = std::max(r.hold_bound, std::clamp(one.front().bound, 0.0, 1.0));
    }
  }
  for (std::size_t w = 0; w < bounds_.size(); ++w) {
    const auto& b = bounds_[w];
    r.waypoint_bounds.push_back(std::clamp(b.bound, 0.0, 1.0));
    if (w == 0 || b.bound > r.max_bound) {
      r.max_bound = std::clamp(b.bound, 0.0, 1.0);
      r.max_waypoint = static_cast<int>(w);
      r.max_time = r.waypoint_times[w];
      r.max_robot_link = b.robot_link >= 0 ? robot_.link_names[static_cast<std::size_t>(b.robot_link)] : "";
      r.max_human_segment = "points";
      r.max_action = moving ? "as seen, moving" : "as seen";
    }
  }
}

}  // namespace iplan::collision_risk
