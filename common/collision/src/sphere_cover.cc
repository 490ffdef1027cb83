#include "iplan/collision/sphere_cover.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace iplan::collision {
namespace {

constexpr double kPi = 3.14159265358979323846;

double SphereVolume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

void RequirePositive(const char* what, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    std::ostringstream msg;
    msg << what << " = " << v << " must be positive and finite";
    throw std::invalid_argument(msg.str());
  }
}

void FillReport(const char* shape, const std::vector<Sphere>& spheres, double volume,
                double excess, CoverReport* report) {
  if (report == nullptr) return;
  report->shape = shape;
  report->num_spheres = static_cast<int>(spheres.size());
  report->shape_volume = volume;
  double sum = 0.0;
  for (const Sphere& s : spheres) sum += SphereVolume(s.radius);
  report->volume_ratio = sum / volume;
  report->max_excess = excess;
}

// Smallest n >= 1 with (half_length / n) <= w_max.
int SlabCount(double half_length, double w_max) {
  return std::max(1, static_cast<int>(std::ceil(half_length / w_max - 1e-12)));
}

}  // namespace

std::string SphereCoverParams::Validate() const {
  std::ostringstream msg;
  if (!(max_radial_excess > 0.0) || !std::isfinite(max_radial_excess)) {
    msg << "max_radial_excess = " << max_radial_excess << " must be positive";
  } else if (!(max_box_cell_half_size > 0.0) || !std::isfinite(max_box_cell_half_size)) {
    msg << "max_box_cell_half_size = " << max_box_cell_half_size << " must be positive";
  }
  return msg.str();
}

std::vector<Sphere> CoverCylinder(double rho, double length, const Eigen::Isometry3d& X_FC,
                                  const SphereCoverParams& params, CoverReport* report) {
  RequirePositive("cylinder radius", rho);
  RequirePositive("cylinder length", length);
  // r - rho <= e  <=>  w <= sqrt((rho + e)^2 - rho^2).
  const double e = params.max_radial_excess;
  const double w_max = std::sqrt((rho + e) * (rho + e) - rho * rho);
  const double h = 0.5 * length;
  const int n = SlabCount(h, w_max);
  const double w = h / n;
  const double r = std::sqrt(rho * rho + w * w);
  std::vector<Sphere> out(n);
  for (int k = 0; k < n; ++k) {
    out[k].centre = X_FC * Eigen::Vector3d(0.0, 0.0, -h + (2 * k + 1) * w);
    out[k].radius = r;
  }
  FillReport("cylinder", out, kPi * rho * rho * length, r - std::min(rho, w), report);
  return out;
}

std::vector<Sphere> CoverCapsule(const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                 double rho, const SphereCoverParams& params,
                                 CoverReport* report) {
  RequirePositive("capsule radius", rho);
  if (!p1.allFinite() || !p2.allFinite()) {
    throw std::invalid_argument("capsule end points must be finite");
  }
  const double L = (p2 - p1).norm();
  const double e = params.max_radial_excess;
  const double w_max = std::sqrt((rho + e) * (rho + e) - rho * rho);
  const int n = L > 0.0 ? SlabCount(0.5 * L, w_max) : 0;
  const double w = n > 0 ? 0.5 * L / n : 0.0;
  const double r = std::sqrt(rho * rho + w * w);
  std::vector<Sphere> out(n + 1);
  for (int k = 0; k <= n; ++k) {
    const double t = n > 0 ? static_cast<double>(k) / n : 0.0;
    out[k].centre = (1.0 - t) * p1 + t * p2;
    out[k].radius = r;
  }
  FillReport("capsule", out, kPi * rho * rho * L + SphereVolume(rho), r - rho, report);
  return out;
}

std::vector<Sphere> CoverBox(const Eigen::Vector3d& half_extents, const Eigen::Isometry3d& X_FB,
                             const SphereCoverParams& params, CoverReport* report) {
  for (int i = 0; i < 3; ++i) RequirePositive("box half extent", half_extents[i]);
  Eigen::Vector3i n;
  Eigen::Vector3d e;
  for (int i = 0; i < 3; ++i) {
    n[i] = SlabCount(half_extents[i], params.max_box_cell_half_size);
    e[i] = half_extents[i] / n[i];
  }
  const double r = e.norm();
  std::vector<Sphere> out;
  out.reserve(static_cast<size_t>(n.prod()));
  for (int i = 0; i < n[0]; ++i) {
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2]; ++k) {
        const Eigen::Vector3d p_B(-half_extents[0] + (2 * i + 1) * e[0],
                                  -half_extents[1] + (2 * j + 1) * e[1],
                                  -half_extents[2] + (2 * k + 1) * e[2]);
        out.push_back({X_FB * p_B, r});
      }
    }
  }
  FillReport("box", out, 8.0 * half_extents.prod(), r - e.minCoeff(), report);
  return out;
}

std::vector<int> RemoveContainedSpheres(std::vector<Sphere>* spheres) {
  const int n = static_cast<int>(spheres->size());
  std::vector<bool> drop(n, false);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n && !drop[a]; ++b) {
      if (a == b || drop[b]) continue;
      const Sphere& sa = (*spheres)[a];
      const Sphere& sb = (*spheres)[b];
      const double d = (sa.centre - sb.centre).norm();
      const bool inside = d + sa.radius <= sb.radius;
      const bool identical = d == 0.0 && sa.radius == sb.radius;
      // Of identical spheres keep the first.
      if (inside && (!identical || b < a)) drop[a] = true;
    }
  }
  std::vector<int> kept;
  std::vector<Sphere> out;
  for (int a = 0; a < n; ++a) {
    if (!drop[a]) {
      kept.push_back(a);
      out.push_back((*spheres)[a]);
    }
  }
  *spheres = std::move(out);
  return kept;
}

}  // namespace iplan::collision
