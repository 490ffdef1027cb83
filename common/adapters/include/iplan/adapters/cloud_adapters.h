// sensor_msgs/PointCloud2 and sensor_msgs/Image (a depth image) <->
// iplan::cloud::Cloud. The framework's Check has
// already refused size mismatches (data vs row_step * height, point_step *
// width vs row_step); here the field layout and the coordinates are checked,
// so that a cloud the core reads is well-formed.
//
// Frame: the cloud's own (header.frame_id, the sensor's optical frame S),
// metres.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "iplan/cloud/camera.h"
#include "iplan/cloud/cloud.h"
#include "iplan/cloud/noise.h"
#include "iplan/msg/types.h"

namespace iplan::services {

/// Decodes x, y, z (FLOAT32, count 1, little-endian, inside point_step) of
/// every point into *out (organised when height > 1). Returns why the cloud
/// is malformed, nullopt when it was decoded: big-endian data, missing or
/// duplicated x/y/z, a coordinate field not FLOAT32 or with count != 1, a
/// field reaching past point_step, point_step under 12 bytes, an infinite
/// coordinate, a point with some but not all coordinates NaN, NaN in a cloud
/// that says is_dense. NaN x, y, z is "no return" (kept, as depth cameras
/// send it). Reuses out's buffers.
std::optional<std::string> FromPointCloud2(const msg::PointCloud2& m, cloud::Cloud* out);

/// The cloud as PointCloud2: fields x, y, z FLOAT32 at offsets 0, 4, 8,
/// point_step 12, little-endian, is_dense when every point is finite.
void ToPointCloud2(const cloud::Cloud& c, const msg::Time& stamp, const std::string& frame_id,
                   msg::PointCloud2* out);

/// Unprojects a depth image (encoding 16UC1: mm, or 32FC1: m; 0 or NaN =
/// no return; little-endian, row-major) of a camera with `intrinsics` into
/// an organised cloud in the image's frame (the optical frame: x right, y
/// down, z forward): pixel (u, v) of depth z is
///   p = ((u - cx) z / fx, (v - cy) z / fy, z),   no return: NaN.
/// Returns why the image cannot be read: another encoding, big-endian, a
/// size other than the intrinsics' width x height, step under width times
/// the pixel's bytes or data other than step x height, a negative or
/// infinite depth (32FC1). Reuses out's buffers.
std::optional<std::string> FromDepthImage(const msg::Image& m, const cloud::CameraIntrinsics& intrinsics,
                                          cloud::Cloud* out);

/// An organised cloud (optical frame) as a 16UC1 depth image: each pixel's
/// z in mm, rounded; no return (NaN) and z outside [0.5 mm, 65.535 m) as 0.
/// Only z is sent, a quarter of the cloud's bytes: the receiver puts each
/// point on its pixel's ray (FromDepthImage), so a point's offset from that
/// ray (the simulated camera's lateral noise) and everything under 1 mm are
/// lost.
void ToDepthImage(const cloud::Cloud& c, const msg::Time& stamp, const std::string& frame_id, msg::Image* out);

/// The pinhole intrinsics of the images a camera's calibration describes,
/// in pixels of those images: fx, fy, cx, cy from k (fx 0 cx; 0 fy cy;
/// 0 0 1), with binning and the region of interest applied as ROS's
/// image_geometry does (fx / binning_x, (cx - roi.x_offset) / binning_x, the
/// image roi.width / binning_x wide, the full width when the region is
/// empty; binning 0 is 1). Returns why they cannot be used, nullopt when
/// *out is set: an image size that is 0 or over 4096 pixels, an
/// uncalibrated camera (k all zero), fx or fy not positive, skew (k[1]) or a
/// k whose last row is not 0 0 1, non-zero distortion coefficients (the
/// images must be rectified: e.g. image_proc's image_rect), a region
/// outside the image.
std::optional<std::string> FromCameraInfo(const msg::CameraInfo& m, cloud::CameraIntrinsics* out);

/// A rectified pinhole camera's calibration: plumb_bob with zero
/// coefficients, k from `intrinsics`, r identity, p = [k | 0], no binning,
/// the whole image.
void ToCameraInfo(const cloud::CameraIntrinsics& intrinsics, const msg::Time& stamp, const std::string& frame_id,
                  msg::CameraInfo* out);

}  // namespace iplan::services
