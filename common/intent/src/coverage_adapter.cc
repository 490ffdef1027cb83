#include "iplan/intent/coverage_adapter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

namespace iplan::intent {
namespace {

// Chi-square quantile with 3 degrees of freedom at 0.95: the 95 % ellipsoid.
constexpr double kChi2Dof3P95 = 7.815;

}  // namespace

std::string CoverageAdapterParams::Validate() const {
  if (!(halving_time >= 0.0) || !std::isfinite(halving_time)) {
    return "halving_time " + std::to_string(halving_time) + " must be >= 0 s (0: off)";
  }
  if (!(target > 0.0 && target < 1.0)) return "target " + std::to_string(target) + " must be in (0, 1)";
  if (!(min_scale > 0.0 && min_scale <= 1.0 && max_scale >= 1.0 && std::isfinite(max_scale))) {
    return "min_scale and max_scale must satisfy 0 < min_scale <= 1 <= max_scale < inf";
  }
  return "";
}

CoverageAdapter::CoverageAdapter(int num_joints, int horizon, double rate, CoverageAdapterParams params)
    : num_joints_(num_joints), horizon_(horizon), rate_(rate), params_(params) {
  if (num_joints < 1 || horizon < 1 || !(rate > 0.0) || !std::isfinite(rate)) {
    throw std::invalid_argument("CoverageAdapter: need num_joints >= 1, horizon >= 1 and rate > 0");
  }
  if (const std::string why = params_.Validate(); !why.empty()) {
    throw std::invalid_argument("CoverageAdapterParams: " + why);
  }
  gain_ = params_.halving_time > 0.0
              ? std::log(2.0) / ((1.0 - params_.target) * rate_ * params_.halving_time)
              : 0.0;
  Reset();
}

void CoverageAdapter::Reset() {
  stored_.clear();
  log_scale_ = Eigen::VectorXd::Zero(num_joints_);
  scale_ = Eigen::VectorXd::Ones(num_joints_);
  outside_ = Eigen::VectorXd::Zero(num_joints_);
  matured_ = Eigen::VectorXd::Zero(num_joints_);
}

void CoverageAdapter::Reset(const Eigen::Ref<const Eigen::VectorXd>& scales) {
  if (scales.size() != num_joints_) {
    throw std::invalid_argument("CoverageAdapter::Reset: " + std::to_string(scales.size()) + " scales, expected " +
                                std::to_string(num_joints_));
  }
  Reset();
  for (int j = 0; j < num_joints_; ++j) {
    // A non-finite scale (never produced here) falls back to the model's.
    if (!std::isfinite(scales(j))) continue;
    scale_(j) = std::clamp(scales(j), params_.min_scale, params_.max_scale);
    log_scale_(j) = std::log(scale_(j));
  }
}

void CoverageAdapter::Observe(double stamp, const Eigen::Ref<const Eigen::VectorXd>& positions) {
  if (positions.size() != 3 * num_joints_) {
    throw std::invalid_argument("CoverageAdapter::Observe: " + std::to_string(positions.size()) +
                                " coordinates, expected " + std::to_string(3 * num_joints_));
  }
  const double dt = 1.0 / rate_, tolerance = 0.25 * dt;
  outside_.setZero();
  matured_.setZero();
  for (Stored& s : stored_) {
    while (s.next_step < horizon_) {
      const double due = s.stamp + (s.next_step + 1) * dt;
      if (stamp < due - tolerance) break;  // not yet
      if (stamp <= due + tolerance) {
        for (int j = 0; j < num_joints_; ++j) {
          const int i = s.next_step * num_joints_ + j;
          const Eigen::Vector3d e = positions.segment<3>(3 * j) - s.mean[i];
          outside_(j) += e.dot(s.inverse[i] * e) > kChi2Dof3P95 ? 1.0 : 0.0;
          matured_(j) += 1.0;
        }
      }
      ++s.next_step;  // scored, or no observation came near its time
    }
  }
  while (!stored_.empty() && stored_.front().next_step >= horizon_) stored_.pop_front();
  if (gain_ == 0.0) return;
  const double miss = 1.0 - params_.target;
  const double lo = std::log(params_.min_scale), hi = std::log(params_.max_scale);
  for (int j = 0; j < num_joints_; ++j) {
    if (matured_(j) == 0.0) continue;
    log_scale_(j) = std::clamp(log_scale_(j) + gain_ * (outside_(j) / matured_(j) - miss), lo, hi);
    scale_(j) = std::exp(log_scale_(j));
  }
}

void CoverageAdapter::Apply(JointMixture* pred) const {
  if (pred->num_joints() != num_joints_ || pred->num_steps != horizon_) {
    throw std::invalid_argument("CoverageAdapter::Apply: prediction of " + std::to_string(pred->num_joints()) +
                                " joints x " + std::to_string(pred->num_steps) + " steps, expected " +
                                std::to_string(num_joints_) + " x " + std::to_string(horizon_));
  }
  for (std::vector<Eigen::Matrix3d>& covariances : pred->covariances) {
    for (int k = 0; k < horizon_; ++k) {
      for (int j = 0; j < num_joints_; ++j) covariances[k * num_joints_ + j] *= scale_(j);
    }
  }
}

void CoverageAdapter::Record(double stamp, const JointMixture& pred) {
  if (pred.num_joints() != num_joints_ || pred.num_steps != horizon_) {
    throw std::invalid_argument("CoverageAdapter::Record: prediction of the wrong size");
  }
  Stored s;
  s.stamp = stamp;
  s.mean.resize(static_cast<size_t>(horizon_) * num_joints_);
  s.inverse.resize(s.mean.size());
  for (int k = 0; k < horizon_; ++k) {
    for (int j = 0; j < num_joints_; ++j) {
      const JointGaussian g = pred.Combined(k, j);
      s.mean[k * num_joints_ + j] = g.mean;
      s.inverse[k * num_joints_ + j] = g.covariance.inverse();
    }
  }
  stored_.push_back(std::move(s));
}

}  // namespace iplan::intent
