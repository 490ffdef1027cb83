// A depth-camera point cloud as iplan passes it around: our own value type,
// so that PCL stays inside iplan::cloud's sources.
//
// Frame: the sensor's optical frame S (x right, y down, z along the viewing
// direction), metres, as depth cameras and PCD files give it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace iplan::cloud {

/// One frame of a depth camera. Organised (an image): `height` rows of
/// `width` points, row-major, points.size() == width * height; unorganised:
/// height == 1. Invalid pixels hold NaN coordinates and are kept, so indices
/// into `points` are the file's point order (and the pixel, when organised).
struct Cloud {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3f> points;  ///< p_SP, metres; NaN = no return
  /// Packed colour 0xAARRGGBB per point when the source had rgb/rgba; empty
  /// otherwise.
  std::vector<std::uint32_t> rgba;
  /// The file's `label` field (ground truth of annotated scans such as mOSD)
  /// when it had one; empty otherwise. Never read by the pipelines.
  std::vector<std::uint32_t> label;

  bool organised() const { return height > 1; }
  std::size_t size() const { return points.size(); }
};

/// Reads a PCD file (any PCD encoding PCL reads: ascii, binary,
/// binary_compressed) with fields x y z and optionally rgb/rgba and label.
/// Throws std::runtime_error naming the file when it cannot be read, has no
/// x y z fields (or they are not float32), has no points, or its width *
/// height does not match its point count.
/// Allocates; thread-safe.
Cloud LoadPcd(const std::string& path);

}  // namespace iplan::cloud
