#include "robot_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace iplan::robot_sim {

std::string SimulatorParams::Validate() const {
  if (!(stopping_time > 0)) return "stopping_time must be > 0";
  if (!(contact_margin >= 0)) return "contact_margin must be >= 0";
  return "";
}

RobotSimulator::RobotSimulator(collision::RobotModel robot, const Eigen::VectorXd& q0, SimulatorParams params)
    : robot_(std::move(robot)), params_(params), data_(robot_) {
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

std::vector<std::string> RobotSimulator::joint_names() const {
  std::vector<std::string> names;
  for (int j : robot_.q_joints) names.push_back(robot_.joints[static_cast<std::size_t>(j)].name);
  return names;
}

std::optional<std::string> RobotSimulator::SetTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                                         const std::vector<double>& times,
                                                         const std::vector<std::vector<double>>& positions) {
  if (times.empty() || times.size() != positions.size()) return std::string("empty or inconsistent trajectory");
  const std::vector<std::string> model = joint_names();
  std::vector<int> idx(model.size(), -1);
  for (std::size_t m = 0; m < model.size(); ++m) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == model[m]) idx[m] = static_cast<int>(i);
    }
    if (idx[m] < 0) return "trajectory lacks joint '" + model[m] + "'";
  }
  Trajectory t;
  t.start_ns = start_ns;
  t.times = times;
  for (std::size_t p = 0; p < positions.size(); ++p) {
    if (positions[p].size() != names.size()) return "point " + std::to_string(p) + " has the wrong size";
    if (p > 0 && !(times[p] > times[p - 1])) return std::string("times do not increase");
    Eigen::VectorXd q(robot_.nq);
    for (int i = 0; i < robot_.nq; ++i) {
      q[i] = positions[p][static_cast<std::size_t>(idx[static_cast<std::size_t>(i)])];
      if (q[i] < lower_[i] - 1e-9 || q[i] > upper_[i] + 1e-9) {
        return "point " + std::to_string(p) + " puts " + model[static_cast<std::size_t>(i)] + " outside its limits";
      }
    }
    t.positions.push_back(q);
  }
  trajectory_ = std::move(t);
  return std::nullopt;
}

void RobotSimulator::Stop() {
  if (stop_requested_) return;
  stop_requested_ = true;
  // Decelerate each joint uniformly to rest within the stopping time.
  stop_decel_ = qd_.cwiseAbs() / params_.stopping_time;
  collision::CalcForwardKinematics(robot_, q_, &data_);
  stop_start_ee_ = data_.X_WL.back().translation();
  last_stopping_distance_ = 0;
}

void RobotSimulator::Resume() { stop_requested_ = false; }

Eigen::VectorXd RobotSimulator::Desired(int64_t now_ns) const {
  if (!trajectory_) return q_;
  const Trajectory& t = *trajectory_;
  const double s = (now_ns - t.start_ns) * 1e-9;
  if (s <= t.times.front()) return t.positions.front();
  if (s >= t.times.back()) return t.positions.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(t.times.begin(), t.times.end(), s) - t.times.begin());
  const double u = (s - t.times[i - 1]) / (t.times[i] - t.times[i - 1]);
  return (1 - u) * t.positions[i - 1] + u * t.positions[i];
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
  double best = 1e6;
  for (int h = 0; h < body.num_spheres(); ++h) {
    const auto& def = body.spheres()[static_cast<std::size_t>(h)];
    const Eigen::Vector3d c = (1 - def.u) * joints.col(def.joint_a) + def.u * joints.col(def.joint_b);
    for (std::size_t k = 0; k < robot_.spheres.size(); ++k) {
      best = std::min(best, (data_.p_WS.col(static_cast<Eigen::Index>(k)) - c).norm() - robot_.spheres[k].radius - def.radius);
    }
  }
  min_separation_seen_ = std::min(min_separation_seen_, best);
  const bool touching = best < params_.contact_margin;
  if (touching && !touching_) ++contacts_;
  touching_ = touching;
  return best;
}

}  // namespace iplan::robot_sim
