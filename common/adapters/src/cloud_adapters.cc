#include "iplan/adapters/cloud_adapters.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "iplan/core/params.h"

namespace iplan::services {
namespace {

// Offsets of x, y, z; why not when the layout is unusable.
std::optional<std::string> CoordinateOffsets(const msg::PointCloud2& m, uint32_t offset[3]) {
  static const char* const kNames[3] = {"x", "y", "z"};
  if (m.is_bigendian) return std::string("big-endian clouds are not supported");
  if (m.point_step < 12) return "point_step " + std::to_string(m.point_step) + " is under 12 bytes (x, y, z float32)";
  bool seen[3] = {false, false, false};
  for (const msg::PointField& f : m.fields) {
    for (int k = 0; k < 3; ++k) {
      if (f.name != kNames[k]) continue;
      if (seen[k]) return "field '" + f.name + "' appears twice";
      seen[k] = true;
      if (f.datatype != msg::PointField::FLOAT32) {
        return "field '" + f.name + "' has datatype " + std::to_string(f.datatype) + ", expected FLOAT32 (7)";
      }
      if (f.count != 1) return "field '" + f.name + "' has count " + std::to_string(f.count) + ", expected 1";
      if (uint64_t{f.offset} + 4 > m.point_step) {
        return "field '" + f.name + "' at offset " + std::to_string(f.offset) + " reaches past point_step " +
               std::to_string(m.point_step);
      }
      offset[k] = f.offset;
    }
  }
  for (int k = 0; k < 3; ++k) {
    if (!seen[k]) return std::string("no field '") + kNames[k] + "'";
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> FromPointCloud2(const msg::PointCloud2& m, cloud::Cloud* out) {
  uint32_t offset[3] = {0, 0, 0};
  if (auto why = CoordinateOffsets(m, offset)) return why;
  // The framework checked row_step * height == data.size() and point_step * width <= row_step.
  if (uint64_t{m.row_step} * m.height != m.data.size() || uint64_t{m.point_step} * m.width > m.row_step) {
    return std::string("data size does not match row_step, point_step, width and height");
  }
  out->width = static_cast<int>(m.width);
  out->height = static_cast<int>(m.height);
  out->points.resize(std::size_t{m.width} * m.height);
  out->rgba.clear();
  out->label.clear();
  std::size_t i = 0;
  for (uint32_t row = 0; row < m.height; ++row) {
    const uint8_t* p = m.data.data() + std::size_t{row} * m.row_step;
    for (uint32_t col = 0; col < m.width; ++col, ++i, p += m.point_step) {
      float v[3];
      int nan = 0;
      for (int k = 0; k < 3; ++k) {
        std::memcpy(&v[k], p + offset[k], sizeof(float));  // little-endian host (x86, arm64)
        if (std::isnan(v[k])) {
          ++nan;
        } else if (!std::isfinite(v[k])) {
          return "point " + std::to_string(i) + " has an infinite coordinate";
        }
      }
      if (nan != 0 && nan != 3) return "point " + std::to_string(i) + " has some coordinates NaN, not all";
      if (nan == 3 && m.is_dense) return "point " + std::to_string(i) + " is NaN in a cloud marked is_dense";
      out->points[i] = Eigen::Vector3f(v[0], v[1], v[2]);
    }
  }
  return std::nullopt;
}

void ToPointCloud2(const cloud::Cloud& c, const msg::Time& stamp, const std::string& frame_id,
                   msg::PointCloud2* out) {
  out->header.stamp = stamp;
  out->header.frame_id = frame_id;
  out->height = static_cast<uint32_t>(c.height);
  out->width = static_cast<uint32_t>(c.width);
  out->fields.resize(3);
  static const char* const kNames[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    out->fields[k].name = kNames[k];
    out->fields[k].offset = static_cast<uint32_t>(4 * k);
    out->fields[k].datatype = msg::PointField::FLOAT32;
    out->fields[k].count = 1;
  }
  out->is_bigendian = false;
  out->point_step = 12;
  out->row_step = 12 * out->width;
  out->data.resize(c.points.size() * 12);
  bool dense = true;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    std::memcpy(out->data.data() + 12 * i, c.points[i].data(), 12);
    dense = dense && c.points[i].allFinite();
  }
  out->is_dense = dense;
}

std::optional<std::string> FromCameraInfo(const msg::CameraInfo& m, cloud::CameraIntrinsics* out) {
  constexpr uint32_t kMaxSide = cloud::CameraIntrinsics::kMaxSide;
  const auto& k = m.k;
  if (std::all_of(k.begin(), k.end(), [](double x) { return x == 0; })) {
    return std::string("the camera is not calibrated (k is all zero)");
  }
  if (!(k[0] > 0) || !(k[4] > 0)) {
    return "focal lengths fx " + core::ParamText(k[0]) + ", fy " + core::ParamText(k[4]) + " are not positive";
  }
  if (k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    return std::string("k is not a pinhole without skew (fx 0 cx; 0 fy cy; 0 0 1)");
  }
  for (double d : m.d) {
    if (d != 0) {
      return "distortion '" + m.distortion_model + "' has non-zero coefficients: the depth images must be rectified";
    }
  }
  const uint32_t bx = std::max(m.binning_x, 1u), by = std::max(m.binning_y, 1u);
  const bool whole = m.roi.width == 0 && m.roi.height == 0;
  const uint64_t roi_w = whole ? m.width : m.roi.width, roi_h = whole ? m.height : m.roi.height;
  if (!whole && (uint64_t{m.roi.x_offset} + roi_w > m.width || uint64_t{m.roi.y_offset} + roi_h > m.height)) {
    return "region of interest " + std::to_string(roi_w) + "x" + std::to_string(roi_h) + " at (" +
           std::to_string(m.roi.x_offset) + ", " + std::to_string(m.roi.y_offset) + ") is outside the " +
           std::to_string(m.width) + "x" + std::to_string(m.height) + " image";
  }
  const uint64_t w = roi_w / bx, h = roi_h / by;
  if (w == 0 || h == 0 || w > kMaxSide || h > kMaxSide) {
    return "image size " + std::to_string(w) + "x" + std::to_string(h) + " is not 1.." + std::to_string(kMaxSide) + " pixels a side";
  }
  const double x0 = whole ? 0.0 : m.roi.x_offset, y0 = whole ? 0.0 : m.roi.y_offset;
  out->width = static_cast<int>(w);
  out->height = static_cast<int>(h);
  out->fx = k[0] / bx;
  out->fy = k[4] / by;
  out->cx = (k[2] - x0) / bx;
  out->cy = (k[5] - y0) / by;
  return std::nullopt;
}

void ToCameraInfo(const cloud::CameraIntrinsics& c, const msg::Time& stamp, const std::string& frame_id,
                  msg::CameraInfo* out) {
  out->header.stamp = stamp;
  out->header.frame_id = frame_id;
  out->width = static_cast<uint32_t>(c.width);
  out->height = static_cast<uint32_t>(c.height);
  out->distortion_model = "plumb_bob";
  out->d.assign(5, 0.0);
  out->k = {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1};
  out->r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  out->p = {c.fx, 0, c.cx, 0, 0, c.fy, c.cy, 0, 0, 0, 1, 0};
  out->binning_x = 0;
  out->binning_y = 0;
  out->roi = msg::RegionOfInterest{};
}

std::optional<std::string> FromDepthImage(const msg::Image& m, const cloud::CameraIntrinsics& intrinsics,
                                          cloud::Cloud* out) {
  const bool mm = m.encoding == "16UC1";
  if (!mm && m.encoding != "32FC1") {
    return "depth image encoding '" + m.encoding + "' is not supported (16UC1 in mm or 32FC1 in m)";
  }
  if (m.is_bigendian) return std::string("big-endian depth images are not supported");
  if (m.width != static_cast<uint32_t>(intrinsics.width) || m.height != static_cast<uint32_t>(intrinsics.height)) {
    return "depth image is " + std::to_string(m.width) + "x" + std::to_string(m.height) + ", the camera's intrinsics " +
           std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height);
  }
  const uint32_t bytes = mm ? 2 : 4;
  if (uint64_t{m.step} < uint64_t{bytes} * m.width || uint64_t{m.step} * m.height != m.data.size()) {
    return "depth image step " + std::to_string(m.step) + " does not fit width " + std::to_string(m.width) + " x " +
           std::to_string(bytes) + " bytes or data " + std::to_string(m.data.size()) + " bytes";
  }
  out->width = static_cast<int>(m.width);
  out->height = static_cast<int>(m.height);
  out->points.resize(std::size_t{m.width} * m.height);
  out->rgba.clear();
  out->label.clear();
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const double ifx = 1.0 / intrinsics.fx, ify = 1.0 / intrinsics.fy;
  std::size_t i = 0;
  for (uint32_t v = 0; v < m.height; ++v) {
    const uint8_t* row = m.data.data() + std::size_t{v} * m.step;
    for (uint32_t u = 0; u < m.width; ++u, ++i) {
      double z;
      if (mm) {
        uint16_t d;
        std::memcpy(&d, row + 2 * u, 2);  // little-endian host (x86, arm64)
        z = d * 1e-3;
      } else {
        float d;
        std::memcpy(&d, row + 4 * u, 4);
        if (std::isnan(d)) d = 0;
        if (!(d >= 0) || !std::isfinite(d)) return "pixel " + std::to_string(i) + " has depth " + std::to_string(d);
        z = d;
      }
      out->points[i] = z > 0 ? Eigen::Vector3f(static_cast<float>((u - intrinsics.cx) * z * ifx),
                                               static_cast<float>((v - intrinsics.cy) * z * ify), static_cast<float>(z))
                             : Eigen::Vector3f(kNaN, kNaN, kNaN);
    }
  }
  return std::nullopt;
}

void ToDepthImage(const cloud::Cloud& c, const msg::Time& stamp, const std::string& frame_id, msg::Image* out) {
  out->header.stamp = stamp;
  out->header.frame_id = frame_id;
  out->height = static_cast<uint32_t>(c.height);
  out->width = static_cast<uint32_t>(c.width);
  out->encoding = "16UC1";
  out->is_bigendian = 0;
  out->step = 2 * out->width;
  out->data.resize(2 * c.points.size());
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    const double z_mm = static_cast<double>(c.points[i].z()) * 1e3;
    const uint16_t d = std::isfinite(z_mm) && z_mm >= 0.5 && z_mm < 65535.5 ? static_cast<uint16_t>(std::lround(z_mm)) : 0;
    std::memcpy(out->data.data() + 2 * i, &d, 2);
  }
}

}  // namespace iplan::services
