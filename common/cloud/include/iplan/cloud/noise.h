// Per-point sensor noise of a Kinect-class structured-light depth camera, so
// that downstream users (the collision bound of METHOD 4 with each point as a
// small Gaussian sphere) can weight a person's points by how well they are
// measured.
//
// Model (a fact, not tuned here): C. V. Nguyen, S. Izadi, D. Lovell,
// "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and Tracking",
// 3DIMPVT 2012, fitted to measurements of a Kinect v1:
//   axial   sigma_z(z)  = 0.0012 + 0.0019 (z - 0.4)^2          [m, z in m]
//   lateral sigma_L     = 0.8 px (for surface angles below ~60 deg),
//           in metres     sigma_L * z / f_x
// Frame: the sensor's optical frame S (z along the view), metres.
#pragma once

#include "iplan/core/name_value.h"

#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/cloud/cloud.h"

namespace iplan::cloud {

struct DepthNoiseParams {
  double axial_constant = 0.0012;   ///< m (Nguyen et al. 2012)
  double axial_quadratic = 0.0019;  ///< 1/m
  double axial_z0 = 0.4;            ///< m, the z of the minimum
  double lateral_px = 0.8;          ///< pixels
  double focal_px = 525.0;          ///< f_x = f_y of a 640x480 Kinect v1, pixels

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(axial_constant, "m; sigma_z = axial_constant + axial_quadratic (z - axial_z0)^2"));
    a->Visit(IPLAN_NVP(axial_quadratic, "1/m"));
    a->Visit(IPLAN_NVP(axial_z0, "m, the depth of the smallest sigma_z"));
    a->Visit(IPLAN_NVP(lateral_px, "pixels; lateral sigma = lateral_px z / focal_px"));
    a->Visit(IPLAN_NVP(focal_px, "pixels, > 0"));
  }
  /// Empty when valid, else the first problem ("focal_px must be > 0").
  std::string Validate() const;
};

/// Axial standard deviation sigma_z(z), metres, for depth z > 0 (metres).
double AxialSigma(const DepthNoiseParams& noise, double z);

/// Covariance of a measured point p_SP (metres, sensor frame), m^2: diag
/// (sigma_L^2, sigma_L^2, sigma_z^2) in S, lateral along x and y, axial along
/// z. Thread-safe, no allocation.
Eigen::Matrix3d PointCovariance(const DepthNoiseParams& noise, const Eigen::Vector3f& p_SP);

/// A set of measured points with their noise (e.g. the person's cluster).
struct NoisyPoints {
  std::vector<Eigen::Vector3f> points;       ///< p_SP, metres, sensor frame
  std::vector<Eigen::Matrix3d> covariances;  ///< m^2, same order
};

/// The points of `cloud` at `indices` (finite ones only) with their
/// covariances. Throws std::out_of_range for an index outside the cloud.
NoisyPoints PointsWithNoise(const Cloud& cloud, const std::vector<int>& indices,
                            const DepthNoiseParams& noise);

}  // namespace iplan::cloud
