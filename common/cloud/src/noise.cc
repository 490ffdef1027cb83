#include "iplan/cloud/noise.h"

#include <cmath>
#include <stdexcept>

namespace iplan::cloud {

std::string DepthNoiseParams::Validate() const {
  if (!(axial_constant >= 0)) return "axial_constant must be >= 0";
  if (!(axial_quadratic >= 0)) return "axial_quadratic must be >= 0";
  if (!std::isfinite(axial_z0)) return "axial_z0 must be finite";
  if (!(lateral_px >= 0)) return "lateral_px must be >= 0";
  if (!(focal_px > 0)) return "focal_px must be > 0";
  return "";
}

double AxialSigma(const DepthNoiseParams& noise, double z) {
  const double d = z - noise.axial_z0;
  return noise.axial_constant + noise.axial_quadratic * d * d;
}

Eigen::Matrix3d PointCovariance(const DepthNoiseParams& noise, const Eigen::Vector3f& p_SP) {
  const double z = p_SP.z();
  const double lateral = noise.lateral_px * z / noise.focal_px;
  const double axial = AxialSigma(noise, z);
  return Eigen::Vector3d(lateral * lateral, lateral * lateral, axial * axial).asDiagonal();
}

NoisyPoints PointsWithNoise(const Cloud& cloud, const std::vector<int>& indices,
                            const DepthNoiseParams& noise) {
  NoisyPoints out;
  out.points.reserve(indices.size());
  out.covariances.reserve(indices.size());
  for (const int i : indices) {
    if (i < 0 || static_cast<std::size_t>(i) >= cloud.size())
      throw std::out_of_range("PointsWithNoise: index " + std::to_string(i) + " outside a cloud of " +
                              std::to_string(cloud.size()) + " points");
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite() || !(p.z() > 0)) continue;
    out.points.push_back(p);
    out.covariances.push_back(PointCovariance(noise, p));
  }
  return out;
}

}  // namespace iplan::cloud
