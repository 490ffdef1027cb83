#include "stages.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "iplan/cloud/oriented_box.h"

namespace iplan::cloud::internal {

KeepTest::KeepTest(const CloudParams& params, const std::vector<Sphere>& robot_spheres)
    : crop_min_(params.crop_min), crop_max_(params.crop_max) {
  for (const Sphere& s : robot_spheres) {
    const float r = s.radius + params.self_filter_margin;
    centres_.push_back(s.centre);
    r2_.push_back(r * r);
  }
}

void KeepMask(const Cloud& cloud, const CloudParams& params, const std::vector<Sphere>& robot_spheres,
              std::vector<std::uint8_t>* keep) {
  const KeepTest kept(params, robot_spheres);
  keep->resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) (*keep)[i] = kept(cloud.points[i]) ? 1 : 0;
}

bool FitPlane(const pcl::PointCloud<pcl::PointXYZ>& sample, int max_iterations, float distance,
              Eigen::Vector4f* plane) {
  if (sample.size() < 3) return false;
  // random = false: PCL seeds RANSAC's generator with a fixed value, so a
  // cloud gives the same plane every run.
  pcl::SACSegmentation<pcl::PointXYZ> sac(/*random=*/false);
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setOptimizeCoefficients(true);
  sac.setMaxIterations(max_iterations);
  sac.setDistanceThreshold(distance);
  // Shared pointer without ownership: the sample outlives the call.
  sac.setInputCloud(pcl::PointCloud<pcl::PointXYZ>::ConstPtr(&sample, [](const void*) {}));
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  sac.segment(inliers, coefficients);
  if (inliers.indices.size() < 3 || coefficients.values.size() != 4) return false;
  Eigen::Vector4f c(coefficients.values[0], coefficients.values[1], coefficients.values[2],
                    coefficients.values[3]);
  const float norm = c.head<3>().norm();
  if (!(norm > 0) || !c.allFinite()) return false;
  c /= norm;
  if (c[3] < 0) c = -c;  // the sensor origin on the positive side
  *plane = c;
  return true;
}

Result BuildResult(const Cloud& cloud, const std::vector<int>& segment, int min_points, bool table_found,
                   const Eigen::Vector4f& plane, const std::vector<int>* group_of) {
  Result result;
  result.labels.assign(cloud.size(), kLabelRemoved);
  int segments = 0;
  for (const int s : segment) segments = std::max(segments, s + 1);
  std::vector<int> count(segments, 0), first(segments, -1);
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const int s = segment[i];
    if (s == kSegTable) {
      result.labels[i] = kLabelTable;
      ++result.table.points;
    } else if (s >= 0) {
      if (count[s]++ == 0) first[s] = static_cast<int>(i);
    }
  }
  std::vector<int> order(segments);
  std::iota(order.begin(), order.end(), 0);
  order.erase(std::remove_if(order.begin(), order.end(), [&](int s) { return count[s] < min_points; }),
              order.end());
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return count[a] != count[b] ? count[a] > count[b] : first[a] < first[b];
  });
  std::vector<int> id_of(segments, 0);
  result.obstacles.resize(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    id_of[order[k]] = static_cast<int>(k) + 1;
    result.obstacles[k].id = static_cast<int>(k) + 1;
    result.obstacles[k].indices.reserve(count[order[k]]);
  }
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const int s = segment[i];
    if (s < 0 || id_of[s] == 0) continue;
    result.labels[i] = LabelOfObstacle(id_of[s]);
    result.obstacles[id_of[s] - 1].indices.push_back(static_cast<int>(i));
  }
  const Eigen::Vector3f up = plane.head<3>();
  std::map<int, int> group_id;  // group_of's id -> 1, 2, ...
  for (std::size_t k = 0; k < order.size(); ++k) {
    Obstacle& o = result.obstacles[k];
    const OrientedBox box = FitOrientedBox(cloud.points, o.indices, table_found ? &up : nullptr);
    o.centre = box.centre;
    o.orientation = box.orientation;
    o.half_extents = box.half_extents;
    const int g = group_of ? (*group_of)[static_cast<std::size_t>(order[k])] : -1 - static_cast<int>(k);
    o.group = group_id.emplace(g, static_cast<int>(group_id.size()) + 1).first->second;
  }
  if (table_found) {
    result.table.found = true;
    result.table.normal = plane.head<3>();
    result.table.offset = plane[3];
  }
  return result;
}

}  // namespace iplan::cloud::internal
