#include "robot_simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace iplan::robot_sim {

std::string SimulatorParams::Validate() const {
  if (!(stopping_time > 0)) return "stopping_time must be > 0";
  if (!(braking_fraction >= 0 && braking_fraction <= 1)) return "braking_fraction must be in [0, 1]";
  if (!(contact_margin >= 0)) return "contact_margin must be >= 0";
  return "";
}

RobotSimulator::RobotSimulator(collision::RobotModel robot, const Eigen::VectorXd& q0, SimulatorParams params)
    : robot_(std::move(robot)), params_(params), data_(robot_), robot_joints_(robot_.JointNames()) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  const int n = robot_.nq;
  if (q0.size() != n) throw std::invalid_argument("initial configuration has " + std::to_string(q0.size()) +
                                                  " joints, the robot " + std::to_string(n));
  lower_ = robot_.LowerLimits();
  upper_ = robot_.UpperLimits();
  vmax_.resize(n);
  amax_.resize(n);
  for (int i = 0; i < n; ++i) {
    const auto& lim = robot_.joints[static_cast<std::size_t>(robot_.q_joints[static_cast<std::size_t>(i)])].limits;
    vmax_[i] = lim.velocity;
    amax_[i] = lim.acceleration;
    if (q0[i] < lower_[i] || q0[i] > upper_[i]) {
      throw std::invalid_argument("initial position of joint " + std::to_string(i + 1) + " outside its limits");
    }
  }
  q_ = q0;
  qd_ = Eigen::VectorXd::Zero(n);
  stop_decel_ = Eigen::VectorXd::Zero(n);
}

std::optional<std::string> RobotSimulator::SetTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                                         const std::vector<double>& times,
                                                         const std::vector<std::vector<double>>& positions) {
  cell::JointTrajectory t;
  if (auto e = cell::JointTrajectory::FromPoints(start_ns, names, times, positions, robot_joints_, &t))
    return "trajectory: " + *e;
  for (std::size_t p = 0; p < t.positions.size(); ++p) {
    const Eigen::VectorXd& q = t.positions[p];
    for (int i = 0; i < robot_.nq; ++i) {
      if (q[i] < lower_[i] - 1e-9 || q[i] > upper_[i] + 1e-9) {
        return "trajectory: point " + std::to_string(p) + " puts " + robot_joints_[static_cast<std::size_t>(i)] +
               " outside its limits";
      }
    }
  }
  trajectory_ = std::move(t);
  lag_ns_ = 0;
  return std::nullopt;
}

void RobotSimulator::Stop() {
  if (stop_requested_) return;
  stop_requested_ = true;
  // Decelerate each joint uniformly so that all come to rest together
  // (the arm stays on its path): within the time the slowest needs at
  // braking_fraction of its acceleration limit, at most the stopping time.
  double duration = params_.stopping_time;
  if (params_.braking_fraction > 0) {
    double needed = 0.0;  // a joint without an acceleration limit brakes over the stopping time
    for (int i = 0; i < robot_.nq; ++i) {
      const double a = params_.braking_fraction * amax_[i];
      needed = std::max(needed, a > 0 && std::isfinite(a) ? std::abs(qd_[i]) / a : params_.stopping_time);
    }
    duration = std::min(duration, needed);
  }
  last_stop_duration_ = duration;
  stop_decel_ = duration > 0 ? Eigen::VectorXd(qd_.cwiseAbs() / duration) : Eigen::VectorXd::Zero(qd_.size());
  collision::CalcForwardKinematics(robot_, q_, &data_);
  stop_start_ee_ = data_.X_WL.back().translation();
  last_stopping_distance_ = 0;
}

void RobotSimulator::Resume() { stop_requested_ = false; }

void RobotSimulator::SetSpeedScale(double scale) {
  speed_scale_ = std::isfinite(scale) ? std::clamp(scale, 0.0, 1.0) : 0.0;
}

Eigen::VectorXd RobotSimulator::Desired(int64_t now_ns) const {
  return trajectory_.empty() ? q_ : trajectory_.PositionAt(now_ns - lag_ns_);
}

void RobotSimulator::Step(int64_t now_ns, double dt) {
  if (!(dt > 0)) return;
  if (stop_requested_) {
    for (int i = 0; i < robot_.nq; ++i) {
      const double dv = stop_decel_[i] * dt;
      qd_[i] = std::abs(qd_[i]) <= dv ? 0.0 : qd_[i] - std::copysign(dv, qd_[i]);
    }
    q_ = (q_ + qd_ * dt).cwiseMax(lower_).cwiseMin(upper_);
    collision::CalcForwardKinematics(robot_, q_, &data_);
    last_stopping_distance_ = std::max(last_stopping_distance_, (data_.X_WL.back().translation() - stop_start_ee_).norm());
    return;
  }
  // Speed reduction: the trajectory's time falls behind by what the scale
  // takes off this step.
  lag_ns_ += static_cast<int64_t>(std::llround((1.0 - speed_scale_) * dt * 1e9));
  // Track the desired position: the velocity that would reach it in one
  // step, limited in velocity and in acceleration, and so that the joint can
  // still stop before overshooting.
  const Eigen::VectorXd target = Desired(now_ns).cwiseMax(lower_).cwiseMin(upper_);
  for (int i = 0; i < robot_.nq; ++i) {
    const double err = target[i] - q_[i];
    const double v_stop = std::sqrt(2 * amax_[i] * std::abs(err));  // fastest speed that can still stop at the target
    double v = std::clamp(err / dt, -std::min(vmax_[i], v_stop), std::min(vmax_[i], v_stop));
    v = std::clamp(v, qd_[i] - amax_[i] * dt, qd_[i] + amax_[i] * dt);
    qd_[i] = v;
  }
  q_ = (q_ + qd_ * dt).cwiseMax(lower_).cwiseMin(upper_);
}

double RobotSimulator::UpdateContacts(const Eigen::Matrix3Xd& joints, const collision::HumanBodyModel& body) {
  collision::CalcForwardKinematics(robot_, q_, &data_);
  double best = std::numeric_limits<double>::infinity();
  for (int h = 0; h < body.num_spheres(); ++h) {
    const Eigen::Vector3d c = body.SphereCentre(h, joints);
    const double human_radius = body.spheres()[static_cast<std::size_t>(h)].radius;
    for (std::size_t k = 0; k < robot_.spheres.size(); ++k) {
      best = std::min(best, (data_.p_WS.col(static_cast<Eigen::Index>(k)) - c).norm() - robot_.spheres[k].radius - human_radius);
    }
  }
  min_separation_seen_ = std::min(min_separation_seen_.value_or(best), best);
  const bool touching = best < params_.contact_margin;
  if (touching && !touching_) ++contacts_;
  touching_ = touching;
  return best;
}

}  // namespace iplan::robot_sim
