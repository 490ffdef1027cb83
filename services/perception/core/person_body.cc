#include "person_body.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace iplan::perception {

double MinJerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10 - 15 * u + 6 * u * u);
}

Eigen::Vector3d ArmElbow(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& hand) {
  const Eigen::Vector3d d = hand - shoulder;
  const double dist = std::clamp(d.norm(), 1e-6, kUpperArm + kForearm - 1e-6);
  const double a = (kUpperArm * kUpperArm - kForearm * kForearm + dist * dist) / (2 * dist);
  const double h = std::sqrt(std::max(0.0, kUpperArm * kUpperArm - a * a));
  const Eigen::Vector3d dir = d.norm() > 1e-9 ? Eigen::Vector3d(d / d.norm()) : Eigen::Vector3d::UnitX();
  Eigen::Vector3d down = Eigen::Vector3d::UnitZ().cross(dir).cross(dir);  // perpendicular, pointing down
  if (down.norm() < 1e-9) down = Eigen::Vector3d::UnitX();
  down.normalize();
  if (down.z() > 0) down = -down;
  return shoulder + a * dir + h * down;
}

}  // namespace iplan::perception
