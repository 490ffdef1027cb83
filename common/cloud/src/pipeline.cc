// Our obstacle pipeline on the organised image (docs/perception-clouds.md):
//  1. keep mask: finite, in the workspace box, not the robot;
//  2. table: RANSAC plane on a strided sample of the kept pixels, then every
//     kept point within a depth-dependent band of the plane is table;
//  3. candidates: kept points above the table (below max_object_height);
//  4. segments: connected components of the candidate pixels in an image
//     strided by `stride`, neighbours joined when close in 3D (a depth
//     discontinuity separates objects), PCL's
//     OrganizedConnectedComponentSegmentation with our comparator;
//  5. parts: the same components with concave creases (from PCL's
//     integral-image normals) also cutting; large parts of one segment stay
//     apart unless they meet convexly or are coplanar (LCCP's criterion on
//     the parts), small ones join their neighbours;
//  6. each full-resolution candidate takes the segment of the closest of the
//     strided pixels around it.
#include <pcl/features/integral_image_normal.h>
#include <pcl/segmentation/comparator.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "iplan/cloud/pipeline.h"
#include "split_segments.h"
#include "stages.h"

namespace iplan::cloud {

using internal::kSegNone;
using internal::kSegTable;

namespace {

using PointCloud = pcl::PointCloud<pcl::PointXYZ>;

/// Joins two neighbouring pixels when their points are closer than
/// cluster_distance + cluster_distance_per_m2 * z^2 (z of the first point)
/// and, when given creases, neither lies on a concave crease (where one
/// object stands on or leans against another). Non-candidate pixels are NaN in the input, so they never join.
class SegmentComparator : public pcl::Comparator<pcl::PointXYZ> {
 public:
  struct Cues {
    const std::vector<std::uint8_t>* crease = nullptr;  // null: no concavity cue
  };
  SegmentComparator(float distance, float per_m2, const Cues& cues)
      : distance_(distance), per_m2_(per_m2), cues_(cues) {}
  bool compare(int a, int b) const override {
    const auto pa = (*input_)[a].getVector3fMap();
    const auto pb = (*input_)[b].getVector3fMap();
    const float z = pa.z();
    const float limit = distance_ + per_m2_ * z * z;
    const float gap2 = (pa - pb).squaredNorm();
    if (!(gap2 < limit * limit)) return false;
    if (cues_.crease && ((*cues_.crease)[a] || (*cues_.crease)[b])) return false;
    return true;
  }

 private:
  float distance_, per_m2_;
  Cues cues_;
};

internal::ConvexityParams Convexity(const CloudParams& p) {
  internal::ConvexityParams c;
  c.flat_cos = std::cos(p.flat_angle_deg * static_cast<float>(M_PI / 180.0));
  c.coplanar_distance = p.coplanar_distance;
  c.convex_margin = p.convex_margin;
  return c;
}

}  // namespace

struct ObstaclePipeline::Impl {
  CloudParams params;
  std::vector<std::uint8_t> keep;
  std::vector<int> segment;
  PointCloud::Ptr sample{new PointCloud};
  PointCloud::Ptr small{new PointCloud};
  pcl::PointCloud<pcl::Label> small_labels;
  std::vector<pcl::PointIndices> small_segments;
  std::vector<int> small_segment;  // strided pixel -> segment or kSegNone
  std::vector<Eigen::Vector3f> small_points;  // the strided image's points

  bool FindTable(const Cloud& cloud, Eigen::Vector4f* plane);
  void MarkTableAndCandidates(const Cloud& cloud, const Eigen::Vector4f& plane, bool table_found);
  pcl::PointCloud<pcl::Normal>::Ptr small_normals{new pcl::PointCloud<pcl::Normal>};
  std::vector<int> Components(const SegmentComparator::Cues& cues);
  std::vector<std::uint8_t> small_crease;  // strided pixel on a concave crease
  void EstimateNormals();
  void MarkCreases();
  void FillCreases(const std::vector<int>& geometric);
  void FillSmall(const Cloud& cloud, int which);
  void SegmentCandidates(const Cloud& cloud);
  void AssignFullResolution(const Cloud& cloud);
};

bool ObstaclePipeline::Impl::FindTable(const Cloud& cloud, Eigen::Vector4f* plane) {
  const int s = params.plane_sample_stride;
  const int w = cloud.width, h = cloud.height;
  sample->clear();
  for (int r = 0; r < h; r += s)
    for (int c = 0; c < w; c += s) {
      const std::size_t i = static_cast<std::size_t>(r) * w + c;
      if (keep[i]) sample->push_back(pcl::PointXYZ(cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z()));
    }
  return internal::FitPlane(*sample, params.plane_max_iterations, params.plane_fit_distance, plane);
}

// segment[i]: kSegTable on the table band, 0 for a candidate (above the
// table), kSegNone otherwise.
void ObstaclePipeline::Impl::MarkTableAndCandidates(const Cloud& cloud, const Eigen::Vector4f& plane,
                                                    bool table_found) {
  segment.assign(cloud.size(), kSegNone);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!keep[i]) continue;
    const Eigen::Vector3f& p = cloud.points[i];
    if (!table_found) {
      segment[i] = 0;
      continue;
    }
    const float d = plane.head<3>().dot(p) + plane[3];
    const float band = internal::TableDistance(params, p.z());
    if (std::abs(d) < band) segment[i] = kSegTable;
    else if (d > 0 && d < params.max_object_height) segment[i] = 0;
  }
}

// Connected components of the strided image (-1 = none), neighbours joined
// by SegmentComparator with `cues`.
std::vector<int> ObstaclePipeline::Impl::Components(const SegmentComparator::Cues& cues) {
  auto comparator = std::make_shared<SegmentComparator>(params.cluster_distance, params.cluster_distance_per_m2, cues);
  comparator->setInputCloud(small);
  pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> occ(comparator);
  occ.setInputCloud(small);
  small_segments.clear();
  // segment() only resize()s the labels, which keeps the previous call's
  // values when the size is unchanged: start from an empty cloud.
  small_labels.clear();
  occ.segment(small_labels, small_segments);
  std::vector<int> out(small->size(), kSegNone);
  for (std::size_t k = 0; k < small_segments.size(); ++k)
    for (const int j : small_segments[k].indices) out[j] = static_cast<int>(k);
  return out;
}

// Normals of the strided image's candidates (PCL's integral-image
// estimator; NaN where undefined).
void ObstaclePipeline::Impl::EstimateNormals() {
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setNormalEstimationMethod(ne.COVARIANCE_MATRIX);
  ne.setNormalSmoothingSize(params.normal_smoothing_px);
  ne.setDepthDependentSmoothing(false);
  ne.setInputCloud(small);
  ne.compute(*small_normals);
  for (std::size_t j = 0; j < small->size(); ++j) {
    pcl::Normal& n = (*small_normals)[j];
    const auto p = (*small)[j].getVector3fMap();
    if (std::isfinite(n.normal_x) && n.getNormalVector3fMap().dot(p) > 0) {
      n.normal_x = -n.normal_x;  // towards the sensor
      n.normal_y = -n.normal_y;
      n.normal_z = -n.normal_z;
    }
  }
}

// A candidate pixel lies on a concave crease when the pixels crease_offset
// to either side of it (along a row or a column) have normals meeting
// concavely: d . (n_b - n_a) < -concave_margin, d the unit vector from a to
// b. A wide baseline sees the crease through the normals' smoothing.
void ObstaclePipeline::Impl::MarkCreases() {
  const int w = static_cast<int>(small->width), h = static_cast<int>(small->height);
  const int k = params.crease_offset_px;
  small_crease.assign(small->size(), 0);
  auto concave = [&](int a, int b) {
    const auto na = (*small_normals)[a].getNormalVector3fMap();
    const auto nb = (*small_normals)[b].getNormalVector3fMap();
    if (!na.allFinite() || !nb.allFinite()) return false;
    const Eigen::Vector3f d = (*small)[b].getVector3fMap() - (*small)[a].getVector3fMap();
    const float len = d.norm();
    return len > 0 && d.dot(nb - na) < -params.concave_margin * len;
  };
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const int i = r * w + c;
      if (!std::isfinite((*small)[i].x)) continue;
      small_crease[i] = (c >= k && c + k < w && concave(i - k, i + k)) ||
                        (r >= k && r + k < h && concave(i - k * w, i + k * w));
    }
}

// Crease pixels (no segment after the split) take the segment of a
// neighbour in the same geometric segment, growing inwards from both sides.
void ObstaclePipeline::Impl::FillCreases(const std::vector<int>& geometric) {
  const int w = static_cast<int>(small->width), h = static_cast<int>(small->height);
  std::vector<int> next = small_segment;
  for (int pass = 0; pass < 2 * params.crease_offset_px + 2; ++pass) {
    bool changed = false;
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const int i = r * w + c;
        if (small_segment[i] != kSegNone || geometric[i] < 0) continue;
        const int nbr[4] = {c > 0 ? i - 1 : -1, c + 1 < w ? i + 1 : -1, r > 0 ? i - w : -1, r + 1 < h ? i + w : -1};
        for (const int j : nbr)
          if (j >= 0 && small_segment[j] != kSegNone && geometric[j] == geometric[i]) {
            next[i] = small_segment[j];
            changed = true;
            break;
          }
      }
    if (!changed) break;
    small_segment = next;
  }
}

// Fills the strided image with the points whose segment is `which` (NaN
// elsewhere).
void ObstaclePipeline::Impl::FillSmall(const Cloud& cloud, int which) {
  const int s = params.stride;
  const int sw = (cloud.width + s - 1) / s, sh = (cloud.height + s - 1) / s;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  small->resize(static_cast<std::size_t>(sw) * sh);
  small->width = sw;
  small->height = sh;
  small->is_dense = false;
  for (int r = 0; r < sh; ++r)
    for (int c = 0; c < sw; ++c) {
      const std::size_t i = static_cast<std::size_t>(r * s) * cloud.width + c * s;
      const Eigen::Vector3f& p = cloud.points[i];
      (*small)[static_cast<std::size_t>(r) * sw + c] =
          segment[i] == which ? pcl::PointXYZ(p.x(), p.y(), p.z()) : pcl::PointXYZ(nan, nan, nan);
    }
}

void ObstaclePipeline::Impl::SegmentCandidates(const Cloud& cloud) {
  const int s = params.stride;
  const int sw = (cloud.width + s - 1) / s, sh = (cloud.height + s - 1) / s;
  FillSmall(cloud, 0);
  const std::vector<int> geometric = Components({});
  // Creases need normals from an image: none for an unorganised cloud (one
  // row) or an image too small for the integral-image window.
  const bool image = sw > 2 * params.crease_offset_px && sh > 2 * params.crease_offset_px;
  if (params.concave_margin >= 2.0f || !image) {
    small_segment = geometric;
    return;
  }
  EstimateNormals();
  if (small_normals->size() != small->size()) {  // PCL refused the input
    small_segment = geometric;
    return;
  }
  MarkCreases();
  SegmentComparator::Cues cues;
  cues.crease = &small_crease;
  const std::vector<int> fragments = Components(cues);
  const int s2 = params.stride * params.stride;
  small_points.resize(small->size());
  for (std::size_t j = 0; j < small->size(); ++j) small_points[j] = (*small)[j].getVector3fMap();
  small_segment = internal::SplitSegments(sw, sh, small_points, geometric, fragments,
                                          (params.min_part_points + s2 - 1) / s2,
                                          Convexity(params));
  FillCreases(geometric);
}

// A candidate at full resolution joins the segment of the closest strided
// pixel among the (up to) four around it, when that one is close enough in
// 3D; otherwise it is removed.
void ObstaclePipeline::Impl::AssignFullResolution(const Cloud& cloud) {
  const int s = params.stride;
  const int sw = static_cast<int>(small->width), sh = static_cast<int>(small->height);
  for (int r = 0; r < cloud.height; ++r)
    for (int c = 0; c < cloud.width; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * cloud.width + c;
      if (segment[i] != 0) continue;
      const Eigen::Vector3f& p = cloud.points[i];
      const float limit = params.cluster_distance + params.cluster_distance_per_m2 * p.z() * p.z();
      float best = limit * limit;
      int chosen = kSegNone;
      const int r0 = r / s, c0 = c / s;
      for (int dr = 0; dr <= 1; ++dr)
        for (int dc = 0; dc <= 1; ++dc) {
          const int rr = r0 + dr, cc = c0 + dc;
          if (rr >= sh || cc >= sw) continue;
          const std::size_t j = static_cast<std::size_t>(rr) * sw + cc;
          if (small_segment[j] == kSegNone) continue;
          const float d2 = ((*small)[j].getVector3fMap() - p).squaredNorm();
          if (d2 < best) {
            best = d2;
            chosen = small_segment[j];
          }
        }
      segment[i] = chosen;
    }
}

ObstaclePipeline::ObstaclePipeline(const CloudParams& params) : impl_(std::make_unique<Impl>()) {
  if (const std::string why = params.Validate(); !why.empty())
    throw std::invalid_argument("ObstaclePipeline: " + why);
  impl_->params = params;
}

ObstaclePipeline::~ObstaclePipeline() = default;

Result ObstaclePipeline::Process(const Cloud& in, const std::vector<Sphere>& robot_spheres) {
  if (static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height) != in.points.size() ||
      in.width < 0 || in.height < 0)
    throw std::invalid_argument("ObstaclePipeline::Process: width * height (" + std::to_string(in.width) +
                                " * " + std::to_string(in.height) + ") != " + std::to_string(in.points.size()) +
                                " points");
  Impl& m = *impl_;
  internal::KeepMask(in, m.params, robot_spheres, &m.keep);
  Eigen::Vector4f plane = Eigen::Vector4f::Zero();
  bool table_found = in.size() > 0 && m.FindTable(in, &plane);
  m.MarkTableAndCandidates(in, plane, table_found);
  if (table_found) {
    long on_table = 0;
    for (const int s : m.segment) on_table += s == kSegTable;
    if (on_table < m.params.min_table_points) {
      table_found = false;
      m.MarkTableAndCandidates(in, plane, false);
    }
  }
  if (in.size() > 0) {
    m.SegmentCandidates(in);
    m.AssignFullResolution(in);
  }
  return internal::BuildResult(in, m.segment, m.params.min_obstacle_points, table_found, plane);
}

}  // namespace iplan::cloud
