// A simulated depth camera: renders spheres (the person's body spheres, the
// robot's collision spheres), boxes and cylinders (the table, scene objects)
// into an organised cloud, ray-cast per pixel within each primitive's image
// bounds (a z-buffer), with the depth-dependent noise of a Kinect-class
// sensor (iplan/cloud/noise.h: Nguyen et al. 2012). No DDS types.
//
// Frames: W the cell frame (`world`), S the camera's optical frame (x right,
// y down, z along the view); the output cloud is in S. Metres.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/cloud/camera.h"
#include "iplan/cloud/cloud.h"
#include "iplan/cloud/noise.h"

namespace iplan::perception {

struct DepthCameraParams {
  cloud::CameraIntrinsics intrinsics;
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();  ///< camera pose in W
  cloud::DepthNoiseParams noise;                           ///< focal_px should equal intrinsics.fx
  bool add_noise = true;
  double min_range = 0.4;   ///< m; nearer returns are NaN (a Kinect sees nothing closer)
  double max_range = 4.0;   ///< m; farther returns are NaN
  uint64_t seed = 1;        ///< noise generator seed
};

/// What the camera sees, in W.
struct DepthScene {
  struct Sphere {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< m
    double radius = 0;                                 ///< m
  };
  struct Box {
    Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();  ///< centre and orientation
    Eigen::Vector3d size = Eigen::Vector3d::Ones();          ///< m, full edge lengths
  };
  struct Cylinder {
    Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();  ///< centre; axis along O's z
    double radius = 0, length = 0;                           ///< m
  };
  std::vector<Sphere> spheres;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
};

class SimulatedDepthCamera {
 public:
  /// Throws std::invalid_argument for invalid intrinsics or noise.
  explicit SimulatedDepthCamera(const DepthCameraParams& params);

  /// Renders one frame into *out (width x height, NaN where nothing is hit
  /// within range). Reuses out's buffers; not thread-safe (one generator).
  void Render(const DepthScene& scene, cloud::Cloud* out);

  const DepthCameraParams& params() const { return params_; }

 private:
  struct Rect {
    int u0, u1, v0, v1;  ///< pixel bounds, inclusive; empty when u0 > u1
  };
  Rect Bounds(const std::vector<Eigen::Vector3d>& corners_S) const;
  Eigen::Vector3d Ray(int u, int v) const;  ///< direction in S with z = 1
  /// hit(ray) returns the depth z of the first intersection, or +inf.
  template <class Hit>
  void Splat(const Rect& r, Hit&& hit);
  void ApplyNoiseAndFill(cloud::Cloud* out);

  DepthCameraParams params_;
  Eigen::Isometry3d X_SW_;
  std::vector<float> depth_;  ///< z per pixel, m; +inf = no hit
  std::mt19937_64 rng_;
};

}  // namespace iplan::perception
