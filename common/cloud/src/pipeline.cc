// Our obstacle pipeline on the organised image (docs/perception-clouds.md):
//  1. kept points: finite, in the workspace box, not the robot (tested where
//     each stage reads a point, not in a pass of its own);
//  2. table: RANSAC plane on a strided sample of the kept pixels, then every
//     kept point within a depth-dependent band of the plane is table;
//  3. candidates: kept points above the table (below max_object_height);
//  4. segments: connected components of the candidate pixels in an image
//     strided by `stride`, neighbours joined when close in 3D (a depth
//     discontinuity separates objects), PCL's
//     OrganizedConnectedComponentSegmentation with our comparator;
//  5. parts: normals by PCA in a window (never across a depth gap); a pixel
//     between two neighbours whose normals meet concavely, or that step
//     between parallel faces, is a crease; connected crease and non-crease
//     pixels form fragments; fragments of at least min_part_points are the
//     parts of their segment (a crease region deep enough is a concave
//     surface, a part too), smaller ones join the part they border most;
//  6. each full-resolution candidate takes the segment of the closest of the
//     strided pixels around it.
#include <pcl/common/eigen.h>
#include <pcl/segmentation/comparator.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>

#include <algorithm>
#include <cmath>
#include <cstring>
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
/// and, when given classes, both have the same non-zero class (crease or
/// not). Non-candidate pixels are NaN in the input, so they never join.
class SegmentComparator : public pcl::Comparator<pcl::PointXYZ> {
 public:
  SegmentComparator(float distance, float per_m2, const std::vector<std::uint8_t>* classes)
      : distance_(distance), per_m2_(per_m2), classes_(classes) {}
  bool compare(int a, int b) const override {
    const auto pa = (*input_)[a].getVector3fMap();
    const auto pb = (*input_)[b].getVector3fMap();
    const float z = pa.z();
    const float limit = distance_ + per_m2_ * z * z;
    const float gap2 = (pa - pb).squaredNorm();
    if (!(gap2 < limit * limit)) return false;
    return !classes_ || ((*classes_)[a] != 0 && (*classes_)[a] == (*classes_)[b]);
  }

 private:
  float distance_, per_m2_;
  const std::vector<std::uint8_t>* classes_;
};

}  // namespace

struct ObstaclePipeline::Impl {
  CloudParams params;
  float step_cos = 1.0f, step_sin = 2.0f;  // from step_normal_deg, step_angle_deg
  std::vector<int> segment;
  PointCloud::Ptr sample{new PointCloud};
  PointCloud::Ptr small{new PointCloud};
  pcl::PointCloud<pcl::Label> small_labels;
  std::vector<pcl::PointIndices> small_segments;
  pcl::PointCloud<pcl::Normal>::Ptr small_normals{new pcl::PointCloud<pcl::Normal>};
  std::vector<std::uint8_t> small_crease;  // strided pixel: 1 non-crease candidate, 2 crease, 0 none
  std::vector<int> small_depth;            // strided crease pixel: chessboard distance to a non-crease one
  std::vector<int> small_segment;          // strided pixel -> segment or kSegNone
  std::vector<int> group_of;               // segment -> its geometric segment (depth-connected)

  bool FindTable(const Cloud& cloud, const internal::KeepTest& kept, Eigen::Vector4f* plane);
  void MarkTableAndCandidates(const Cloud& cloud, const internal::KeepTest& kept, const Eigen::Vector4f& plane,
                              bool table_found);
  std::vector<int> Components(const std::vector<std::uint8_t>* classes);
  void EstimateNormals();
  bool Crease(int a, int b) const;
  void MarkCreases();
  void MeasureCreaseDepth();
  void FillSmall(const Cloud& cloud, int which);
  void SegmentCandidates(const Cloud& cloud);
  void AssignFullResolution(const Cloud& cloud);
};

// The kept points are tested where they are used (the strided sample here,
// every point in MarkTableAndCandidates), not in a pass of their own: the
// cloud is read from memory once less.
bool ObstaclePipeline::Impl::FindTable(const Cloud& cloud, const internal::KeepTest& kept, Eigen::Vector4f* plane) {
  const int s = params.plane_sample_stride;
  const int w = cloud.width, h = cloud.height;
  sample->clear();
  for (int r = 0; r < h; r += s)
    for (int c = 0; c < w; c += s) {
      const std::size_t i = static_cast<std::size_t>(r) * w + c;
      if (kept(cloud.points[i])) sample->push_back(pcl::PointXYZ(cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z()));
    }
  return internal::FitPlane(*sample, params.plane_max_iterations, params.plane_fit_distance, plane);
}

// segment[i]: kSegTable on the table band, 0 for a candidate (above the
// table), kSegNone otherwise.
void ObstaclePipeline::Impl::MarkTableAndCandidates(const Cloud& cloud, const internal::KeepTest& kept,
                                                    const Eigen::Vector4f& plane, bool table_found) {
  segment.assign(cloud.size(), kSegNone);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!kept(p)) continue;
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
// by SegmentComparator with `classes` (may be null).
std::vector<int> ObstaclePipeline::Impl::Components(const std::vector<std::uint8_t>* classes) {
  auto comparator = std::make_shared<SegmentComparator>(params.cluster_distance, params.cluster_distance_per_m2, classes);
  comparator->setInputCloud(small);
  pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> occ(comparator);
  occ.setInputCloud(small);
  small_segments.clear();
  // segment() only resize()s the labels to PCL's invalid label (all bits
  // set), which keeps the previous call's values when the size is
  // unchanged: set them all to it first. One memset, not the element-wise
  // fill resize() does from empty (7 % of the pipeline's time).
  static_assert(sizeof(pcl::Label) == sizeof(std::uint32_t));
  small_labels.resize(small->size());
  std::memset(static_cast<void*>(small_labels.data()), 0xFF, small_labels.size() * sizeof(pcl::Label));
  occ.segment(small_labels, small_segments);
  std::vector<int> out(small->size(), kSegNone);
  for (std::size_t k = 0; k < small_segments.size(); ++k)
    for (const int j : small_segments[k].indices) out[j] = static_cast<int>(k);
  return out;
}

// Normals of the strided image's candidates: PCA of the candidates in a
// window of normal_window_px strided pixels around each (every other
// pixel of it), taking only
// those reachable without a depth gap (within m * the joining distance, m
// the window ring), so a normal never mixes two surfaces a depth
// discontinuity separates. NaN where fewer than 5 points qualify.
void ObstaclePipeline::Impl::EstimateNormals() {
  const int w = static_cast<int>(small->width), h = static_cast<int>(small->height);
  const int m = params.normal_window_px;
  small_normals->resize(small->size());
  small_normals->width = small->width;
  small_normals->height = small->height;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const int i = r * w + c;
      pcl::Normal& n = (*small_normals)[i];
      n.normal_x = n.normal_y = n.normal_z = nan;
      const Eigen::Vector3f pi = (*small)[i].getVector3fMap();
      if (!std::isfinite(pi.x())) continue;
      const float limit = params.cluster_distance + params.cluster_distance_per_m2 * pi.z() * pi.z();
      // Every other pixel of the window (the normal barely changes, the
      // cost is a quarter); coordinates relative to the centre, so float
      // sums keep their precision.
      float sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;
      int count = 0;
      const int step = m >= 2 ? 2 : 1;
      for (int dr = -m; dr <= m; dr += step) {
        const int rr = r + dr;
        if (rr < 0 || rr >= h) continue;
        for (int dc = -m; dc <= m; dc += step) {
          const int cc = c + dc;
          if (cc < 0 || cc >= w) continue;
          const Eigen::Vector3f q = (*small)[rr * w + cc].getVector3fMap() - pi;
          if (!std::isfinite(q.x())) continue;
          const float ring = static_cast<float>(std::max(std::abs(dr), std::abs(dc)));
          if (q.squaredNorm() > ring * ring * limit * limit) continue;
          sx += q.x(), sy += q.y(), sz += q.z();
          sxx += q.x() * q.x(), sxy += q.x() * q.y(), sxz += q.x() * q.z();
          syy += q.y() * q.y(), syz += q.y() * q.z(), szz += q.z() * q.z();
          ++count;
        }
      }
      const Eigen::Vector3d sum(sx, sy, sz);
      Eigen::Matrix3d outer;
      outer << sxx, sxy, sxz, sxy, syy, syz, sxz, syz, szz;
      if (count < 5) continue;
      const Eigen::Vector3d mean = sum / count;
      const Eigen::Matrix3f cov = (outer / count - mean * mean.transpose()).cast<float>();
      // The normal: the eigenvector of the smallest eigenvalue, as PCL's
      // normal estimation takes it (pcl::eigen33, in float).
      float smallest = 0;
      Eigen::Vector3f v;
      pcl::eigen33(cov, smallest, v);
      if (v.dot(pi) > 0) v = -v;  // towards the sensor
      n.normal_x = v.x();
      n.normal_y = v.y();
      n.normal_z = v.z();
    }
}

// Whether strided pixels a and b (2 crease_offset_px apart) have a crease
// between them: their normals meet concavely, d . (n_b - n_a) <
// -concave_margin |d| (d from a to b), or they are within step_normal_deg
// of each other while d leaves their mean tangent plane by more than
// step_angle_deg (a step between parallel faces). False where a normal is
// undefined.
bool ObstaclePipeline::Impl::Crease(int a, int b) const {
  const auto na = (*small_normals)[a].getNormalVector3fMap();
  const auto nb = (*small_normals)[b].getNormalVector3fMap();
  if (!na.allFinite() || !nb.allFinite()) return false;
  const Eigen::Vector3f d = (*small)[b].getVector3fMap() - (*small)[a].getVector3fMap();
  const float len = d.norm();
  if (!(len > 0)) return false;
  if (d.dot(nb - na) < -params.concave_margin * len) return true;
  return na.dot(nb) > step_cos && std::abs((na + nb).normalized().dot(d)) > step_sin * len;
}

// small_crease: 2 for a candidate pixel with a crease between the pixels
// crease_offset_px to either side of it (along a row or a column; a wide
// baseline sees the crease through the normals' window), 1 for the other
// candidates, 0 elsewhere.
void ObstaclePipeline::Impl::MarkCreases() {
  const int w = static_cast<int>(small->width), h = static_cast<int>(small->height);
  const int k = params.crease_offset_px;
  small_crease.assign(small->size(), 0);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const int i = r * w + c;
      if (!std::isfinite((*small)[i].x)) continue;
      const bool crease = (c >= k && c + k < w && Crease(i - k, i + k)) ||
                          (r >= k && r + k < h && Crease(i - k * w, i + k * w));
      small_crease[i] = crease ? 2 : 1;
    }
}

// small_depth: for a crease pixel, the chessboard distance to the nearest
// non-crease candidate (two-pass chamfer; huge when there is none); 0 for
// the others.
void ObstaclePipeline::Impl::MeasureCreaseDepth() {
  const int w = static_cast<int>(small->width), h = static_cast<int>(small->height);
  constexpr int kFar = 1 << 20;
  small_depth.assign(small->size(), 0);
  for (std::size_t j = 0; j < small->size(); ++j) small_depth[j] = small_crease[j] == 2 ? kFar : 0;
  for (int pass = 0; pass < 2; ++pass) {
    const int dir = pass == 0 ? -1 : 1;  // forward pass looks back, backward pass ahead
    for (int t = 0; t < w * h; ++t) {
      const int j = pass == 0 ? t : w * h - 1 - t;
      if (!small_depth[j]) continue;
      const int r = j / w, c = j % w, rr = r + dir;
      int& d = small_depth[j];
      auto relax = [&](int q) {
        if (small_crease[q] == 1) d = 1;
        else if (small_crease[q] == 2) d = std::min(d, small_depth[q] + 1);
      };
      if (c + dir >= 0 && c + dir < w) relax(j + dir);
      if (rr >= 0 && rr < h) {
        relax(j + dir * w);
        if (c > 0) relax(j + dir * w - 1);
        if (c + 1 < w) relax(j + dir * w + 1);
      }
    }
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
  const std::vector<int> geometric = Components(nullptr);
  // Creases need an image: none for an unorganised cloud (one row) or an
  // image too small for the crease baseline.
  const bool image = sw > 2 * params.crease_offset_px && sh > 2 * params.crease_offset_px;
  const bool cues = params.concave_margin < 2.0f || params.step_angle_deg < 90.0f;
  if (!cues || !image) {
    small_segment = geometric;
    group_of.resize(small->size());
    for (std::size_t j = 0; j < group_of.size(); ++j) group_of[j] = static_cast<int>(j);
    return;
  }
  EstimateNormals();
  MarkCreases();
  MeasureCreaseDepth();
  // Fragments: connected pixels of one kind. A crease fragment is a band
  // along a crease (joins its neighbours) unless enough of it lies deeper
  // than concave_region_depth_px inside it and it borders at most one
  // large other fragment: then it is a concave surface (the inside of a
  // bowl or a mug, bordering its outside), a part of its own.
  const std::vector<int> fragments = Components(&small_crease);
  int nf = 0;
  for (const int f : fragments) nf = std::max(nf, f + 1);
  std::vector<int> interior(nf, 0);
  std::vector<std::uint8_t> may_core(nf, 1);
  for (std::size_t j = 0; j < small->size(); ++j) {
    const int f = fragments[j];
    if (f < 0 || small_crease[j] != 2) continue;
    may_core[f] = 0;
    if (small_depth[j] > params.concave_region_depth_px) ++interior[f];
  }
  const int s2 = params.stride * params.stride;
  const int min_core = (params.min_part_points + s2 - 1) / s2;
  // How many large non-crease fragments each crease fragment borders: a
  // band between two surfaces borders two, a concave surface at most one
  // (the outside of its own container).
  std::vector<int> size(nf, 0);
  for (const int f : fragments)
    if (f >= 0) ++size[f];
  std::vector<std::pair<int, int>> touching;  // (crease fragment, large non-crease fragment)
  for (int r = 0; r < sh; ++r)
    for (int c = 0; c < sw; ++c) {
      const int i = r * sw + c;
      for (const int j : {c + 1 < sw ? i + 1 : -1, r + 1 < sh ? i + sw : -1}) {
        if (j < 0 || fragments[i] < 0 || fragments[j] < 0 || geometric[i] != geometric[j]) continue;
        const int a = fragments[i], b = fragments[j];
        if (small_crease[i] == 2 && small_crease[j] == 1 && size[b] >= min_core) touching.emplace_back(a, b);
        if (small_crease[j] == 2 && small_crease[i] == 1 && size[a] >= min_core) touching.emplace_back(b, a);
      }
    }
  std::sort(touching.begin(), touching.end());
  touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
  std::vector<int> neighbours(nf, 0);
  for (const auto& t : touching) ++neighbours[t.first];
  for (int f = 0; f < nf; ++f)
    if (!may_core[f] && interior[f] >= params.concave_region_share * min_core &&
        neighbours[f] <= 1)
      may_core[f] = 1;
  small_segment = internal::SplitSegments(sw, sh, geometric, fragments, min_core, may_core);
  group_of.assign(static_cast<std::size_t>(std::max(nf, 1)), kSegNone);
  for (std::size_t j = 0; j < small->size(); ++j)
    if (small_segment[j] >= 0) group_of[static_cast<std::size_t>(small_segment[j])] = geometric[j];
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
  const float deg = static_cast<float>(M_PI / 180.0);
  impl_->step_cos = std::cos(params.step_normal_deg * deg);
  impl_->step_sin = params.step_angle_deg >= 90.0f ? 2.0f : std::sin(params.step_angle_deg * deg);
}

ObstaclePipeline::~ObstaclePipeline() = default;

Result ObstaclePipeline::Process(const Cloud& in, const std::vector<Sphere>& robot_spheres) {
  if (static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height) != in.points.size() ||
      in.width < 0 || in.height < 0)
    throw std::invalid_argument("ObstaclePipeline::Process: width * height (" + std::to_string(in.width) +
                                " * " + std::to_string(in.height) + ") != " + std::to_string(in.points.size()) +
                                " points");
  Impl& m = *impl_;
  const internal::KeepTest kept(m.params, robot_spheres);
  Eigen::Vector4f plane = Eigen::Vector4f::Zero();
  bool table_found = in.size() > 0 && m.FindTable(in, kept, &plane);
  m.MarkTableAndCandidates(in, kept, plane, table_found);
  if (table_found) {
    long on_table = 0;
    for (const int s : m.segment) on_table += s == kSegTable;
    if (on_table < m.params.min_table_points) {
      table_found = false;
      m.MarkTableAndCandidates(in, kept, plane, false);
    }
  }
  if (in.size() > 0) {
    m.SegmentCandidates(in);
    m.AssignFullResolution(in);
  }
  if (in.size() == 0) m.group_of.clear();
  return internal::BuildResult(in, m.segment, m.params.min_obstacle_points, table_found, plane, &m.group_of);
}

}  // namespace iplan::cloud
