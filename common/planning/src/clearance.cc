#include "clearance.h"

#include <cmath>

namespace iplan::planning::internal {

ClearanceObject MakeClearanceObject(const collision::SceneObject& o) {
  ClearanceObject c;
  c.box = o.shape == collision::SceneObject::Shape::kBox;
  c.X_OW = o.X_WO.inverse();
  c.R_WO = o.X_WO.linear();
  c.centre_W = o.X_WO.translation();
  if (c.box) {
    c.half = 0.5 * o.size;
    c.bounding_radius = c.half.norm();
  } else {
    c.radius = o.radius;
    c.half_length = 0.5 * o.length;
    c.bounding_radius = std::hypot(c.radius, c.half_length);
  }
  return c;
}

namespace {
inline double Sign(double v) { return v < 0.0 ? -1.0 : 1.0; }
}  // namespace

double PointSignedDistance(const ClearanceObject& o, const Eigen::Vector3d& p_W,
                           Eigen::Vector3d* grad_W) {
  const Eigen::Vector3d p = o.X_OW * p_W;
  Eigen::Vector3d g_O;
  double d;
  if (o.box) {
    const Eigen::Vector3d q = p.cwiseAbs() - o.half;
    int axis;
    const double qmax = q.maxCoeff(&axis);
    if (qmax > 0.0) {
      const Eigen::Vector3d qc = q.cwiseMax(0.0);
      d = qc.norm();
      for (int i = 0; i < 3; ++i) g_O[i] = Sign(p[i]) * qc[i] / d;
    } else {
      d = qmax;
      g_O.setZero();
      g_O[axis] = Sign(p[axis]);
    }
  } else {
    const double r = std::hypot(p.x(), p.y());
    const Eigen::Vector3d u =
        r > 1e-12 ? Eigen::Vector3d(p.x() / r, p.y() / r, 0.0) : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d ez(0.0, 0.0, Sign(p.z()));
    const double qr = r - o.radius, qz = std::abs(p.z()) - o.half_length;
    if (qr > 0.0 || qz > 0.0) {
      const double a = std::max(qr, 0.0), b = std::max(qz, 0.0);
      d = std::hypot(a, b);
      g_O = (a * u + b * ez) / d;
    } else if (qr > qz) {
      d = qr;
      g_O = u;
    } else {
      d = qz;
      g_O = ez;
    }
  }
  if (grad_W != nullptr) *grad_W = o.R_WO * g_O;
  return d;
}

}  // namespace iplan::planning::internal
