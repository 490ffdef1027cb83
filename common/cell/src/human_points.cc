#include "iplan/cell/human_points.h"

#include <Eigen/Eigenvalues>

namespace iplan::cell {

std::optional<std::string> HumanPoints::Check() const {
  const std::size_t n = static_cast<std::size_t>(size());
  if (covariances.size() != n) {
    return std::to_string(covariances.size()) + " covariances for " + std::to_string(n) + " points";
  }
  if (!motion_of.empty() && motion_of.size() != n) {
    return "motion_of has " + std::to_string(motion_of.size()) + " entries for " + std::to_string(n) + " points";
  }
  for (std::size_t i = 0; i < motion_of.size(); ++i) {
    if (motion_of[i] < -1 || motion_of[i] >= static_cast<int>(motions.size())) {
      return "point " + std::to_string(i) + " names motion " + std::to_string(motion_of[i]) + " of " +
             std::to_string(motions.size());
    }
  }
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const PointMotion& m = motions[k];
    if (!m.velocity.allFinite() || !m.covariance.allFinite()) return "motion " + std::to_string(k) + " is not finite";
    const double scale = 1.0 + m.covariance.cwiseAbs().maxCoeff();
    if ((m.covariance - m.covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
      return "motion " + std::to_string(k) + ": velocity covariance not symmetric";
    }
    const Eigen::Matrix3d sym = 0.5 * (m.covariance + m.covariance.transpose());
    if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(sym, Eigen::EigenvaluesOnly).eigenvalues().minCoeff() <
        -1e-9 * scale) {
      return "motion " + std::to_string(k) + ": velocity covariance not positive semi-definite";
    }
  }
  return std::nullopt;
}

}  // namespace iplan::cell
