#include "iplan/cloud/oriented_box.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace iplan::cloud {
namespace {

constexpr float kPi = static_cast<float>(M_PI);

// A unit vector perpendicular to u: F's x axis projected onto the plane
// normal to u, or F's y axis when x is (nearly) along u.
Eigen::Vector3f PlaneAxis(const Eigen::Vector3f& u) {
  Eigen::Vector3f e = Eigen::Vector3f::UnitX() - u.x() * u;
  if (e.norm() < 1e-3f) e = Eigen::Vector3f::UnitY() - u.y() * u;
  return e.normalized();
}

// Area of the footprint's bounding rectangle with its sides along
// (cos t, sin t) and (-sin t, cos t) of the 2D points.
float FootprintArea(const std::vector<Eigen::Vector2f>& q, float t) {
  const float c = std::cos(t), s = std::sin(t);
  float a0 = std::numeric_limits<float>::max(), a1 = -a0, b0 = a0, b1 = -a0;
  for (const Eigen::Vector2f& p : q) {
    const float a = c * p.x() + s * p.y(), b = -s * p.x() + c * p.y();
    a0 = std::min(a0, a), a1 = std::max(a1, a), b0 = std::min(b0, b), b1 = std::max(b1, b);
  }
  return (a1 - a0) * (b1 - b0);
}

// The box with axes R (columns) holding every point.
OrientedBox Fit(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices, const Eigen::Matrix3f& R) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const int i : indices) {
    const Eigen::Vector3f p_B = R.transpose() * points[static_cast<std::size_t>(i)];
    lo = lo.cwiseMin(p_B);
    hi = hi.cwiseMax(p_B);
  }
  OrientedBox box;
  box.centre = R * (0.5f * (lo + hi));
  box.orientation = Eigen::Quaternionf(R).normalized();
  box.half_extents = (0.5f * (hi - lo)).cwiseMax(0.0f);
  return box;
}

// Up given: z along up, the yaw with the smallest footprint.
Eigen::Matrix3f UprightAxes(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices,
                            const Eigen::Vector3f& up) {
  const Eigen::Vector3f u = up.normalized();
  const Eigen::Vector3f e1 = PlaneAxis(u), e2 = u.cross(e1);
  const std::size_t step = std::max<std::size_t>(1, (indices.size() + 255) / 256);
  std::vector<Eigen::Vector2f> q;
  q.reserve(indices.size() / step + 1);
  for (std::size_t k = 0; k < indices.size(); k += step) {
    const Eigen::Vector3f& p = points[static_cast<std::size_t>(indices[k])];
    q.emplace_back(p.dot(e1), p.dot(e2));
  }
  // Rectangles repeat every 90 degrees: a coarse search, then a fine one.
  float best = 0, best_area = std::numeric_limits<float>::max();
  auto search = [&](float from, float to, float by) {
    for (float t = from; t < to + 1e-6f; t += by) {
      const float a = FootprintArea(q, t);
      if (a < best_area) best_area = a, best = t;
    }
  };
  const float deg = kPi / 180.0f;
  search(0.0f, 88.0f * deg, 2.0f * deg);
  search(best - 2.0f * deg, best + 2.0f * deg, 0.25f * deg);
  Eigen::Vector3f x = std::cos(best) * e1 + std::sin(best) * e2;
  Eigen::Vector3f y = u.cross(x);
  // The longer side is x.
  float xmin = std::numeric_limits<float>::max(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (const int i : indices) {
    const Eigen::Vector3f& p = points[static_cast<std::size_t>(i)];
    xmin = std::min(xmin, p.dot(x)), xmax = std::max(xmax, p.dot(x));
    ymin = std::min(ymin, p.dot(y)), ymax = std::max(ymax, p.dot(y));
  }
  if (ymax - ymin > xmax - xmin) {
    const Eigen::Vector3f old_x = x;
    x = y;
    y = -old_x;
  }
  if (x.dot(e1) < 0) {  // e1 is F's x axis in the plane (or its y axis)
    x = -x;
    y = -y;
  }
  Eigen::Matrix3f R;
  R << x, y, u;
  return R;
}

// No up: the principal axes.
Eigen::Matrix3f PrincipalAxes(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : indices) mean += points[static_cast<std::size_t>(i)].cast<double>();
  mean /= static_cast<double>(indices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d d = points[static_cast<std::size_t>(i)].cast<double>() - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);  // eigenvalues ascending
  Eigen::Vector3f x = eig.eigenvectors().col(2).cast<float>(), y = eig.eigenvectors().col(1).cast<float>();
  if (x.x() < 0) x = -x;
  if (y.y() < 0) y = -y;
  Eigen::Matrix3f R;
  R << x, y, x.cross(y);
  return R;
}

}  // namespace

OrientedBox FitOrientedBox(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices,
                           const Eigen::Vector3f* up) {
  if (indices.empty()) return {};
  const Eigen::Matrix3f R = up ? UprightAxes(points, indices, *up) : PrincipalAxes(points, indices);
  return Fit(points, indices, R);
}

}  // namespace iplan::cloud
