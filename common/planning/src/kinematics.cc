#include "iplan/planning/kinematics.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Cholesky>

namespace iplan::planning {

using collision::JointType;
using collision::RobotData;
using collision::RobotModel;

KinematicChains::KinematicChains(const RobotModel& model) : model_(&model) {
  const int num_links = static_cast<int>(model.link_names.size());
  chains_.resize(num_links);
  for (int link = 0; link < num_links; ++link) {
    for (int l = link; l >= 0;) {
      const int j = model.link_parent_joint[l];
      if (j < 0) break;
      const collision::Joint& joint = model.joints[j];
      if (joint.type != JointType::kFixed) {
        Entry e;
        e.joint = j;
        e.revolute = joint.type == JointType::kRevolute;
        if (joint.q_index >= 0) {
          e.q_index = joint.q_index;
        } else if (joint.mimic_q_index >= 0) {
          e.q_index = joint.mimic_q_index;
          e.multiplier = joint.mimic_multiplier;
        }
        if (e.q_index >= 0) chains_[link].push_back(e);
      }
      l = joint.parent_link;
    }
  }
}

namespace {
// Axis (W) of joint j: the child frame's rotation applied to the joint axis
// (the joint's own motion leaves its axis fixed); its origin is the child
// frame's origin (a rotation about an axis through the joint origin keeps it).
inline Eigen::Vector3d AxisW(const RobotModel& m, const RobotData& d, int j) {
  return d.X_WL[m.joints[j].child_link].linear() * m.joints[j].axis;
}
}  // namespace

void KinematicChains::CalcPointJacobian(
    const RobotData& data, int link, const Eigen::Vector3d& p_WP,
    Eigen::Ref<Eigen::Matrix<double, 3, Eigen::Dynamic>> J) const {
  J.setZero();
  for (const Entry& e : chains_[link]) {
    const Eigen::Vector3d a = AxisW(*model_, data, e.joint);
    if (e.revolute) {
      const Eigen::Vector3d o = data.X_WL[model_->joints[e.joint].child_link].translation();
      J.col(e.q_index) += e.multiplier * a.cross(p_WP - o);
    } else {
      J.col(e.q_index) += e.multiplier * a;
    }
  }
}

void KinematicChains::AddPointGradient(const RobotData& data, int link,
                                       const Eigen::Vector3d& p_WP, const Eigen::Vector3d& g,
                                       Eigen::Ref<Eigen::VectorXd> grad_q) const {
  for (const Entry& e : chains_[link]) {
    const Eigen::Vector3d a = AxisW(*model_, data, e.joint);
    if (e.revolute) {
      const Eigen::Vector3d o = data.X_WL[model_->joints[e.joint].child_link].translation();
      grad_q[e.q_index] += e.multiplier * g.dot(a.cross(p_WP - o));
    } else {
      grad_q[e.q_index] += e.multiplier * g.dot(a);
    }
  }
}

void KinematicChains::CalcRotationJacobian(
    const RobotData& data, int link, Eigen::Ref<Eigen::Matrix<double, 3, Eigen::Dynamic>> J) const {
  J.setZero();
  for (const Entry& e : chains_[link]) {
    if (e.revolute) J.col(e.q_index) += e.multiplier * AxisW(*model_, data, e.joint);
  }
}

namespace {

Eigen::Vector3d RotationError(const Eigen::Matrix3d& R_target, const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R_target * R.transpose());
  return aa.angle() * aa.axis();
}

// The rotation vector (world frame) that turns the unit axis a onto a_target
// by the shortest way (its angle is the error).
Eigen::Vector3d AxisError(const Eigen::Vector3d& a, const Eigen::Vector3d& a_target) {
  Eigen::Vector3d c = a.cross(a_target);
  const double angle = std::atan2(c.norm(), a.dot(a_target));
  if (c.norm() < 1e-12) {
    if (angle < 1.0) return Eigen::Vector3d::Zero();
    c = a.unitOrthogonal();  // opposite: any perpendicular axis
  }
  return angle * c.normalized();
}

}  // namespace

IkResult SolveIk(const KinematicChains& chains, int link, const Eigen::Vector3d& p_LE,
                 const Eigen::Isometry3d& X_WE_target, const Eigen::VectorXd& q_seed,
                 const IkOptions& options, std::mt19937_64* rng) {
  const RobotModel& model = chains.model();
  const int nq = model.nq;
  if (link < 0 || link >= static_cast<int>(model.link_names.size()))
    throw std::invalid_argument("SolveIk: link index " + std::to_string(link) + " out of range");
  if (q_seed.size() != nq)
    throw std::invalid_argument("SolveIk: seed has " + std::to_string(q_seed.size()) +
                                " joints, the robot has " + std::to_string(nq));
  if (!q_seed.allFinite() || !X_WE_target.matrix().allFinite() || !p_LE.allFinite())
    throw std::invalid_argument("SolveIk: non-finite seed or target");
  if (rng == nullptr) throw std::invalid_argument("SolveIk: rng must not be null");
  const bool axis_only = options.align_axis_L.squaredNorm() > 0.0;
  if (axis_only && (!options.align_axis_L.allFinite() || std::abs(options.align_axis_L.norm() - 1.0) > 1e-6))
    throw std::invalid_argument("SolveIk: align_axis_L must be a finite unit vector");

  Eigen::VectorXd lo = model.LowerLimits().array() + options.position_margin;
  Eigen::VectorXd hi = model.UpperLimits().array() - options.position_margin;
  RobotData data(model);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, nq);
  IkResult best;
  best.q = q_seed.cwiseMax(lo).cwiseMin(hi);
  double best_score = std::numeric_limits<double>::infinity();
  const Eigen::Matrix3d R_target = X_WE_target.linear();
  const Eigen::Vector3d p_target = X_WE_target.translation();

  for (int attempt = 0; attempt <= options.restarts; ++attempt) {
    Eigen::VectorXd q(nq);
    if (attempt == 0) {
      q = best.q;
    } else {
      for (int i = 0; i < nq; ++i) {
        std::uniform_real_distribution<double> u(std::isfinite(lo[i]) ? lo[i] : -M_PI,
                                                 std::isfinite(hi[i]) ? hi[i] : M_PI);
        q[i] = u(*rng);
      }
    }
    for (int it = 0; it < options.max_iterations; ++it) {
      ++best.iterations;
      collision::CalcForwardKinematics(model, q, &data);
      const Eigen::Isometry3d& X_WL = data.X_WL[link];
      const Eigen::Vector3d p = X_WL * p_LE;
      Eigen::Matrix<double, 6, 1> e;
      e.head<3>() = p_target - p;
      const Eigen::Vector3d axis_W = X_WL.linear() * options.align_axis_L;
      e.tail<3>() = axis_only ? AxisError(axis_W, R_target * options.align_axis_L)
                              : RotationError(R_target, X_WL.linear());
      const double ep = e.head<3>().norm(), eo = e.tail<3>().norm();
      const double score = ep + 0.1 * eo;
      if (score < best_score) {
        best_score = score;
        best.q = q;
        best.position_error = ep;
        best.orientation_error = eo;
      }
      if (ep <= options.position_tolerance && eo <= options.orientation_tolerance) {
        best.success = true;
        return best;
      }
      chains.CalcPointJacobian(data, link, p, J.topRows<3>());
      chains.CalcRotationJacobian(data, link, J.bottomRows<3>());
      // Turning about the free axis changes nothing that is asked for.
      if (axis_only) J.bottomRows<3>() = (Eigen::Matrix3d::Identity() - axis_W * axis_W.transpose()) * J.bottomRows<3>();
      Eigen::Matrix<double, 6, 6> A = J * J.transpose();
      A.diagonal().array() += options.damping * options.damping;
      Eigen::VectorXd dq = J.transpose() * A.ldlt().solve(e);
      const double norm = dq.norm();
      if (norm > 0.5) dq *= 0.5 / norm;
      q = (q + dq).cwiseMax(lo).cwiseMin(hi);
    }
  }
  return best;
}

}  // namespace iplan::planning
