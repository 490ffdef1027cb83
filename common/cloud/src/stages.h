// Stages both pipelines share (internal: PCL types allowed here).
#pragma once

#include <cstdint>
#include <vector>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "iplan/cloud/pipeline.h"

namespace iplan::cloud::internal {

/// Which points a pipeline keeps: finite, inside the crop box and outside
/// every robot sphere grown by params.self_filter_margin.
class KeepTest {
 public:
  KeepTest(const CloudParams& params, const std::vector<Sphere>& robot_spheres);
  bool operator()(const Eigen::Vector3f& p) const {
    if (!p.allFinite()) return false;
    if ((p.array() < crop_min_.array()).any() || (p.array() > crop_max_.array()).any()) return false;
    for (std::size_t s = 0; s < centres_.size(); ++s)
      if ((p - centres_[s]).squaredNorm() <= r2_[s]) return false;
    return true;
  }

 private:
  Eigen::Vector3f crop_min_, crop_max_;
  std::vector<Eigen::Vector3f> centres_;
  std::vector<float> r2_;  // squared grown radii
};

/// keep[i] = 1 when KeepTest keeps point i, else 0. Resizes *keep.
void KeepMask(const Cloud& cloud, const CloudParams& params, const std::vector<Sphere>& robot_spheres,
              std::vector<std::uint8_t>* keep);

/// RANSAC plane fit (PCL SACSegmentation, coefficients refined on the
/// inliers) on `sample`. On success, *plane = (n, d) with |n| = 1 and the
/// sensor origin on the positive side (d > 0). False when there is no plane
/// with at least 3 inliers. `sample` must be non-empty for success.
bool FitPlane(const pcl::PointCloud<pcl::PointXYZ>& sample, int max_iterations, float distance,
              Eigen::Vector4f* plane);

/// Table band half-width at depth z (metres).
inline float TableDistance(const CloudParams& p, float z) {
  return p.table_distance + p.table_distance_per_m2 * (z * z - 1.0f > 0 ? z * z - 1.0f : 0.0f);
}

/// Segment ids per input point: kSegTable, kSegNone or a segment >= 0.
constexpr int kSegNone = -1;
constexpr int kSegTable = -2;

/// Turns per-point segment ids into a Result: segments with fewer than
/// `min_points` points are removed; the others become obstacles numbered
/// 1, 2, ... by decreasing size (ties by first index), each with the
/// oriented box of its points (upright on the table when `table_found`)
/// and its group: group_of[segment] (any ids; renumbered 1, 2, ... in the
/// order of the obstacles), or each obstacle its own group when group_of
/// is null. `plane` is written to the table when `table_found`. Allocates.
Result BuildResult(const Cloud& cloud, const std::vector<int>& segment, int min_points, bool table_found,
                   const Eigen::Vector4f& plane, const std::vector<int>* group_of = nullptr);

}  // namespace iplan::cloud::internal
