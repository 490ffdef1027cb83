// A pinhole depth camera's geometry: intrinsics and its pose in the cell,
// shared by the simulated camera (perception) and the cloud stage, so both
// name the same optical frame the same way.
//
// Frames: W the cell frame (`world`, z up), S the camera's optical frame
// (x right, y down, z along the view). Metres, pixels where named.
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/core/name_value.h"

namespace iplan::cloud {

/// Pinhole intrinsics of a depth image (no distortion).
struct CameraIntrinsics {
  static constexpr int kMaxSide = 4096;  ///< pixels, the largest width or height accepted
  int width = 640;    ///< pixels
  int height = 480;   ///< pixels
  double fx = 525.0;  ///< focal length, pixels (Kinect v1 at 640x480)
  double fy = 525.0;  ///< pixels
  double cx = 319.5;  ///< principal point, pixels
  double cy = 239.5;  ///< pixels

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(width, "pixels, 1..4096"));
    a->Visit(IPLAN_NVP(height, "pixels, 1..4096"));
    a->Visit(IPLAN_NVP(fx, "pixels, focal length, > 0"));
    a->Visit(IPLAN_NVP(fy, "pixels, > 0"));
    a->Visit(IPLAN_NVP(cx, "pixels, principal point"));
    a->Visit(IPLAN_NVP(cy, "pixels"));
  }
  /// Empty when valid, else the first problem ("fx must be > 0, got 0").
  std::string Validate() const;
};

/// X_WS of a camera at p_WC looking at p_WT, with the image's "up" as close
/// to +z of W as the view allows (x_S = z_S x z_W normalised, y_S = z_S x
/// x_S). Throws
/// std::invalid_argument when the points coincide or the view is vertical.
Eigen::Isometry3d CameraPoseLookAt(const Eigen::Vector3d& p_WC, const Eigen::Vector3d& p_WT);

/// A camera's pose as a config gives it: where it is and what it looks at
/// (m, W); Pose() is CameraPoseLookAt of the two.
struct CameraLookAt {
  std::array<double, 3> position = {0.45, 1.3, 1.1};
  std::array<double, 3> look_at = {0.6, 0.0, 0.1};

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(position, "m, W; the camera's optical centre"));
    a->Visit(IPLAN_NVP(look_at, "m, W; the point the view is centred on (image up as close to +z as the view allows)"));
  }
  /// X_WS. Throws std::invalid_argument as CameraPoseLookAt does.
  Eigen::Isometry3d Pose() const {
    return CameraPoseLookAt({position[0], position[1], position[2]}, {look_at[0], look_at[1], look_at[2]});
  }
  /// Empty when valid, else the reason (coinciding points, a vertical view).
  std::string Validate() const {
    try {
      Pose();
    } catch (const std::invalid_argument& e) {
      return std::string("camera: ") + e.what();
    }
    return "";
  }
};

/// Voxel-grid reduction (PCL VoxelGrid): the centroid of the points in each
/// occupied cube of edge `leaf` (m, > 0) of a grid aligned with the points'
/// frame; points must be finite. Order: PCL's (by voxel index). Allocates.
std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points, float leaf);

}  // namespace iplan::cloud
