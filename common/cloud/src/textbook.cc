// The textbook PCL pipeline (as in PCL's cluster-extraction tutorial): crop,
// 1 cm voxel grid, RANSAC plane on the voxels, Euclidean clustering of the
// rest. Each input point takes the label of its voxel.
#include <pcl/filters/voxel_grid.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <limits>

#include "iplan/cloud/pipeline.h"
#include "stages.h"

namespace iplan::cloud {

using internal::kSegNone;
using internal::kSegTable;

Result TextbookPipeline(const Cloud& cloud, const CloudParams& params,
                        const std::vector<Sphere>& robot_spheres) {
  using PointCloud = pcl::PointCloud<pcl::PointXYZ>;
  std::vector<std::uint8_t> keep;
  internal::KeepMask(cloud, params, robot_spheres, &keep);
  PointCloud::Ptr kept(new PointCloud);
  std::vector<int> source;  // kept point -> input index
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!keep[i]) continue;
    const Eigen::Vector3f& p = cloud.points[i];
    kept->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    source.push_back(static_cast<int>(i));
  }
  std::vector<int> segment(cloud.size(), kSegNone);
  if (kept->empty()) return internal::BuildResult(cloud, segment, 1, false, Eigen::Vector4f::Zero());

  PointCloud::Ptr voxels(new PointCloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(kept);
  grid.setLeafSize(params.voxel_size, params.voxel_size, params.voxel_size);
  grid.setSaveLeafLayout(true);
  grid.filter(*voxels);

  Eigen::Vector4f plane = Eigen::Vector4f::Zero();
  const bool fitted = internal::FitPlane(*voxels, params.plane_max_iterations, params.plane_fit_distance, &plane);
  std::vector<int> voxel_segment(voxels->size(), kSegNone);
  auto rest = std::make_shared<pcl::Indices>();
  long table_voxels = 0;
  for (std::size_t v = 0; v < voxels->size(); ++v) {
    const float d = fitted ? plane.head<3>().dot((*voxels)[v].getVector3fMap()) + plane[3]
                           : std::numeric_limits<float>::infinity();
    if (std::abs(d) < params.plane_fit_distance) {
      voxel_segment[v] = kSegTable;
      ++table_voxels;
    } else {
      rest->push_back(static_cast<int>(v));
    }
  }
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(voxels, rest);
  std::vector<pcl::PointIndices> clusters;
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(params.euclidean_tolerance);
  ec.setMinClusterSize(params.textbook_min_cluster);
  ec.setMaxClusterSize(std::numeric_limits<int>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(voxels);
  ec.setIndices(rest);
  ec.extract(clusters);
  for (std::size_t c = 0; c < clusters.size(); ++c)
    for (const int v : clusters[c].indices) voxel_segment[v] = static_cast<int>(c);

  for (std::size_t k = 0; k < kept->size(); ++k) {
    const int v = grid.getCentroidIndex((*kept)[k]);
    if (v >= 0 && static_cast<std::size_t>(v) < voxel_segment.size()) segment[source[k]] = voxel_segment[v];
  }
  const bool table_found = fitted && table_voxels > 0;
  if (!table_found)
    for (int& s : segment)
      if (s == kSegTable) s = kSegNone;
  return internal::BuildResult(cloud, segment, 1, table_found, plane);
}

}  // namespace iplan::cloud
