// Camera geometry helpers and the voxel-grid reduction (PCL VoxelGrid).
#include <pcl/filters/voxel_grid.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "iplan/cloud/camera.h"
#include "iplan/core/params.h"

namespace iplan::cloud {
namespace {
std::string Num(double v) { return core::ParamText(v); }
}  // namespace

std::string CameraIntrinsics::Validate() const {
  const std::string range = "1.." + std::to_string(kMaxSide) + " pixels, got ";
  if (width < 1 || width > kMaxSide) return "width must be in " + range + std::to_string(width);
  if (height < 1 || height > kMaxSide) return "height must be in " + range + std::to_string(height);
  if (!(std::isfinite(fx) && fx > 0)) return "fx must be > 0, got " + Num(fx);
  if (!(std::isfinite(fy) && fy > 0)) return "fy must be > 0, got " + Num(fy);
  if (!std::isfinite(cx) || !std::isfinite(cy)) return "cx and cy must be finite";
  return "";
}

Eigen::Isometry3d CameraPoseLookAt(const Eigen::Vector3d& p_WC, const Eigen::Vector3d& p_WT) {
  const Eigen::Vector3d view = p_WT - p_WC;
  if (!view.allFinite() || view.norm() < 1e-6)
    throw std::invalid_argument("camera position and look-at point must be finite and apart");
  const Eigen::Vector3d z = view.normalized();
  const Eigen::Vector3d x_raw = z.cross(Eigen::Vector3d::UnitZ());
  if (x_raw.norm() < 1e-3) throw std::invalid_argument("camera must not look straight up or down");
  const Eigen::Vector3d x = x_raw.normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();
  X_WS.linear().col(0) = x;
  X_WS.linear().col(1) = y;
  X_WS.linear().col(2) = z;
  X_WS.translation() = p_WC;
  return X_WS;
}

std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points, float leaf) {
  if (!(leaf > 0)) throw std::invalid_argument("voxel leaf must be > 0");
  using PointCloud = pcl::PointCloud<pcl::PointXYZ>;
  PointCloud::Ptr in(new PointCloud);
  in->reserve(points.size());
  for (const auto& p : points) in->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  std::vector<Eigen::Vector3f> out;
  if (in->empty()) return out;
  PointCloud voxels;
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(in);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.filter(voxels);
  out.reserve(voxels.size());
  for (const auto& v : voxels) out.emplace_back(v.x, v.y, v.z);
  return out;
}

}  // namespace iplan::cloud
