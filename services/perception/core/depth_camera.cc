#include "services/perception/core/depth_camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace iplan::perception {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Ray p(t) = t d (from the origin) against the sphere |p - c| = r; smallest t > 0.
double HitSphere(const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r) {
  const double a = d.squaredNorm(), b = d.dot(c), k = c.squaredNorm() - r * r;
  const double disc = b * b - a * k;
  if (disc < 0) return kInf;
  const double s = std::sqrt(disc);
  const double t0 = (b - s) / a, t1 = (b + s) / a;
  return t0 > 0 ? t0 : (t1 > 0 ? t1 : kInf);
}

// Ray o + t d against the box |x_i| <= h_i (slab test); smallest t > 0.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& h) {
  double lo = 0, hi = kInf;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-12) {
      if (std::abs(o[i]) > h[i]) return kInf;
      continue;
    }
    double t0 = (-h[i] - o[i]) / d[i], t1 = (h[i] - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
    if (lo > hi) return kInf;
  }
  return lo > 0 ? lo : kInf;
}

// Ray o + t d against the cylinder x^2 + y^2 <= r^2, |z| <= l / 2; smallest t > 0.
double HitCylinder(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double l) {
  double best = kInf;
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a > 1e-12) {
    const double b = o.x() * d.x() + o.y() * d.y(), k = o.x() * o.x() + o.y() * o.y() - r * r;
    const double disc = b * b - a * k;
    if (disc >= 0) {
      for (double t : {(-b - std::sqrt(disc)) / a, (-b + std::sqrt(disc)) / a}) {
        if (t > 0 && std::abs(o.z() + t * d.z()) <= l / 2) best = std::min(best, t);
      }
    }
  }
  if (std::abs(d.z()) > 1e-12) {
    for (double zc : {-l / 2, l / 2}) {
      const double t = (zc - o.z()) / d.z();
      const Eigen::Vector3d p = o + t * d;
      if (t > 0 && p.x() * p.x() + p.y() * p.y() <= r * r) best = std::min(best, t);
    }
  }
  return best;
}

std::vector<Eigen::Vector3d> BoxCorners(const Eigen::Isometry3d& X_SO, const Eigen::Vector3d& h) {
  std::vector<Eigen::Vector3d> c;
  for (int i = 0; i < 8; ++i) {
    c.push_back(X_SO * Eigen::Vector3d((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z()));
  }
  return c;
}

}  // namespace

SimulatedDepthCamera::SimulatedDepthCamera(const DepthCameraParams& params)
    : params_(params), X_SW_(params.X_WS.inverse()), rng_(params.seed) {
  if (auto why = params.intrinsics.Validate(); !why.empty()) throw std::invalid_argument("intrinsics: " + why);
  if (auto why = params.noise.Validate(); !why.empty()) throw std::invalid_argument("noise: " + why);
  if (!(params.min_range >= 0 && params.min_range < params.max_range))
    throw std::invalid_argument("min_range must be >= 0 and below max_range");
}

Eigen::Vector3d SimulatedDepthCamera::Ray(int u, int v) const {
  const cloud::CameraIntrinsics& k = params_.intrinsics;
  return {(u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0};
}

SimulatedDepthCamera::Rect SimulatedDepthCamera::Bounds(const std::vector<Eigen::Vector3d>& corners_S) const {
  const cloud::CameraIntrinsics& k = params_.intrinsics;
  Rect r{0, k.width - 1, 0, k.height - 1};
  double u0 = kInf, u1 = -kInf, v0 = kInf, v1 = -kInf;
  for (const Eigen::Vector3d& p : corners_S) {
    if (p.z() < 1e-3) return r;  // reaches behind the camera: test every pixel
    const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  }
  r.u0 = std::max(0, static_cast<int>(std::floor(u0)));
  r.u1 = std::min(k.width - 1, static_cast<int>(std::ceil(u1)));
  r.v0 = std::max(0, static_cast<int>(std::floor(v0)));
  r.v1 = std::min(k.height - 1, static_cast<int>(std::ceil(v1)));
  return r;
}

template <class Hit>
void SimulatedDepthCamera::Splat(const Rect& r, Hit&& hit) {
  const int w = params_.intrinsics.width;
  for (int v = r.v0; v <= r.v1; ++v) {
    for (int u = r.u0; u <= r.u1; ++u) {
      const double z = hit(Ray(u, v));
      float& d = depth_[static_cast<std::size_t>(v) * w + u];
      if (z < d) d = static_cast<float>(z);
    }
  }
}

void SimulatedDepthCamera::Render(const DepthScene& scene, cloud::Cloud* out) {
  const cloud::CameraIntrinsics& k = params_.intrinsics;
  depth_.assign(static_cast<std::size_t>(k.width) * k.height, std::numeric_limits<float>::infinity());
  for (const DepthScene::Sphere& s : scene.spheres) {
    const Eigen::Vector3d c = X_SW_ * s.centre;
    Eigen::Isometry3d X_SO = Eigen::Isometry3d::Identity();
    X_SO.translation() = c;
    Splat(Bounds(BoxCorners(X_SO, Eigen::Vector3d::Constant(s.radius))),
          [&](const Eigen::Vector3d& d) { return HitSphere(d, c, s.radius); });
  }
  for (const DepthScene::Box& b : scene.boxes) {
    const Eigen::Isometry3d X_SO = X_SW_ * b.X_WO;
    const Eigen::Isometry3d X_OS = X_SO.inverse();
    const Eigen::Vector3d h = b.size / 2, o = X_OS.translation();
    const Eigen::Matrix3d R_OS = X_OS.linear();
    Splat(Bounds(BoxCorners(X_SO, h)), [&](const Eigen::Vector3d& d) { return HitBox(o, R_OS * d, h); });
  }
  for (const DepthScene::Cylinder& c : scene.cylinders) {
    const Eigen::Isometry3d X_SO = X_SW_ * c.X_WO;
    const Eigen::Isometry3d X_OS = X_SO.inverse();
    const Eigen::Vector3d o = X_OS.translation();
    const Eigen::Matrix3d R_OS = X_OS.linear();
    Splat(Bounds(BoxCorners(X_SO, Eigen::Vector3d(c.radius, c.radius, c.length / 2))),
          [&](const Eigen::Vector3d& d) { return HitCylinder(o, R_OS * d, c.radius, c.length); });
  }
  ApplyNoiseAndFill(out);
}

void SimulatedDepthCamera::ApplyNoiseAndFill(cloud::Cloud* out) {
  const cloud::CameraIntrinsics& k = params_.intrinsics;
  out->width = k.width;
  out->height = k.height;
  out->points.resize(depth_.size());
  out->rgba.clear();
  out->label.clear();
  std::normal_distribution<float> normal(0.0f, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * k.width + u;
      double z = depth_[i];
      if (!(z >= params_.min_range && z <= params_.max_range)) {
        out->points[i].setConstant(nan);
        continue;
      }
      double du = 0, dv = 0;
      if (params_.add_noise) {
        z += cloud::AxialSigma(params_.noise, z) * normal(rng_);
        du = params_.noise.lateral_px * normal(rng_);  // lateral noise, pixels
        dv = params_.noise.lateral_px * normal(rng_);
      }
      out->points[i] = Eigen::Vector3f(static_cast<float>((u + du - k.cx) / k.fx * z),
                                       static_cast<float>((v + dv - k.cy) / k.fy * z), static_cast<float>(z));
    }
  }
}

}  // namespace iplan::perception
