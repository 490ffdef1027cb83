#include "iplan/safety/ssm.h"

#include <algorithm>
#include <cmath>

namespace iplan::safety {

std::string SsmParams::Validate() const {
  for (double v : {default_human_speed, speed_window, reaction_time, stopping_time, stopping_distance,
                   intrusion_distance, sensing_uncertainty, robot_uncertainty}) {
    if (!(v >= 0)) return "ISO/TS 15066 parameters must be >= 0";
  }
  if (!(speed_window > 0)) return "speed_window must be > 0";
  if (!(stopping_speed > 0)) return "stopping_speed must be > 0";
  if (!std::isfinite(retreat_speed)) return "retreat_speed must be finite";
  if (!(min_speed_scale > 0 && min_speed_scale <= 1)) return "min_speed_scale must be in (0, 1]";
  if (!(speed_reduction_time >= 0) || !std::isfinite(speed_reduction_time)) return "speed_reduction_time must be >= 0";
  return "";
}

double StoppingDistance(const SsmParams& p, double v_r) {
  return p.directed ? p.stopping_distance * std::min(1.0, v_r / p.stopping_speed) : p.stopping_distance;
}

double ProtectiveSeparationDistance(const SsmParams& p, double v_h, double v_r) {
  const double s_h = v_h * (p.reaction_time + p.stopping_time);
  const double s_r = v_r * p.reaction_time;
  const double fixed = p.intrusion_distance + p.sensing_uncertainty + p.robot_uncertainty;
  return s_h + s_r + StoppingDistance(p, v_r) + fixed;
}

double SpeedScaleFor(const SsmParams& p, double d, double v_h, double v_r) {
  const double at_rest = ProtectiveSeparationDistance(p, v_h, 0.0);
  if (!(d >= at_rest)) return 0.0;
  if (!(v_r > 0.0) || d >= ProtectiveSeparationDistance(p, v_h, v_r)) return 1.0;
  // S_p grows linearly with the robot's speed: directed, with slope
  // T_r + S_s / stopping_speed up to stopping_speed and T_r above it;
  // undirected (S_s already in at_rest), with slope T_r. Here S_p(v_r) > d,
  // so the slope used is positive.
  const double room = d - at_rest;
  double v = 0.0;
  if (p.directed) {
    const double slope = p.reaction_time + p.stopping_distance / p.stopping_speed;
    v = room / slope;
    if (v > p.stopping_speed) v = p.stopping_speed + (room - slope * p.stopping_speed) / p.reaction_time;
  } else {
    v = room / p.reaction_time;
  }
  return std::clamp(v / v_r, 0.0, 1.0);
}

SsmPair SsmPairRule(const SsmParams& p, const Eigen::Vector3d& delta, double radii, const Eigen::Vector3d& v_human,
                    const Eigen::Vector3d& v_robot) {
  SsmPair r;
  const double centres = delta.norm();
  r.separation = centres - radii;
  const Eigen::Vector3d u = centres > 1e-9 ? Eigen::Vector3d(delta / centres) : Eigen::Vector3d::Zero();  // human -> robot
  r.v_h = std::max(0.0, v_human.dot(u));
  const double away = v_robot.dot(u);  // the robot sphere's speed away from the human sphere
  r.v_r = std::max(0.0, -away);
  r.protective_separation = ProtectiveSeparationDistance(p, r.v_h, r.v_r);
  r.margin = r.separation - r.protective_separation;
  r.retreating = r.margin < 0 && p.retreat_speed > 0 && centres > 1e-9 && away >= p.retreat_speed;
  if (!r.retreating) {
    r.stop_scale = SpeedScaleFor(p, r.separation, r.v_h, r.v_r);
    r.slow_scale = SpeedScaleFor(p, r.separation - r.v_r * p.speed_reduction_time, r.v_h, r.v_r);
  }
  return r;
}

}  // namespace iplan::safety
