#include "services/cloud/core/cloud_stage.h"

#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "iplan/cloud/camera.h"
#include "iplan/cloud/oriented_box.h"

namespace iplan::cloud_service {

std::string CloudStageParams::Validate() const {
  if (auto why = pipeline.Validate(); !why.empty()) return "pipeline: " + why;
  if (auto why = noise.Validate(); !why.empty()) return "noise: " + why;
  if (auto why = tracking.Validate(); !why.empty()) return "tracking: " + why;
  if (auto why = motion.Validate(); !why.empty()) return "motion: " + why;
  if (!X_WS.matrix().allFinite()) return "camera pose must be finite";
  for (int k = 0; k < 3; ++k) {
    if (!(workspace_min[k] < workspace_max[k])) return "workspace_min must be below workspace_max on every axis";
  }
  if (!(human_voxel >= 0 && std::isfinite(human_voxel))) return "human_voxel must be >= 0 m";
  return "";
}

CloudStage::CloudStage(const CloudStageParams& params, const collision::RobotModel* robot)
    : params_(params),
      X_SW_(params.X_WS.inverse()),
      pipeline_(params.pipeline),
      tracker_(params.tracking),
      motion_(params.motion) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (robot) {
    robot_ = std::make_unique<collision::RobotModel>(*robot);
    robot_data_ = std::make_unique<collision::RobotData>(*robot_);
  }
}

CloudStage::~CloudStage() = default;

std::vector<std::string> CloudStage::JointNames() const { return robot_ ? robot_->JointNames() : std::vector<std::string>{}; }

void CloudStage::Crop(cloud::Cloud* cloud, StageOutput* out) const {
  const Eigen::Matrix3f R = params_.X_WS.linear().cast<float>();
  const Eigen::Vector3f t = params_.X_WS.translation().cast<float>();
  const Eigen::Vector3f lo = params_.workspace_min.cast<float>(), hi = params_.workspace_max.cast<float>();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (Eigen::Vector3f& p_S : cloud->points) {
    if (!p_S.allFinite()) continue;
    const Eigen::Vector3f p_W = R * p_S + t;
    if ((p_W.array() < lo.array()).any() || (p_W.array() > hi.array()).any()) {
      p_S.setConstant(nan);
      ++out->cropped_points;
    }
  }
}

std::vector<cloud::Sphere> CloudStage::RobotSpheres(const Eigen::VectorXd& q, const std::vector<Eigen::VectorXd>& around) {
  std::vector<cloud::Sphere> spheres;
  if (!robot_ || q.size() != robot_->nq || !q.allFinite()) return spheres;
  collision::CalcForwardKinematics(*robot_, q, robot_data_.get());
  const Eigen::Matrix3Xd p_WS = robot_data_->p_WS;
  Eigen::VectorXd grow = Eigen::VectorXd::Zero(p_WS.cols());
  for (const Eigen::VectorXd& qa : around) {
    if (qa.size() != robot_->nq || !qa.allFinite()) continue;
    collision::CalcForwardKinematics(*robot_, qa, robot_data_.get());
    grow = grow.cwiseMax((robot_data_->p_WS - p_WS).colwise().norm().transpose());
  }
  spheres.reserve(robot_->spheres.size());
  for (std::size_t i = 0; i < robot_->spheres.size(); ++i) {
    const Eigen::Index k = static_cast<Eigen::Index>(i);
    cloud::Sphere s;
    s.centre = (X_SW_ * p_WS.col(k)).cast<float>();
    s.radius = static_cast<float>(robot_->spheres[i].radius + grow[k]);
    spheres.push_back(s);
  }
  return spheres;
}

void CloudStage::HumanPoints(const cloud::Cloud& cloud, const std::vector<int>& indices, bool track, int64_t stamp_ns,
                             StageOutput* out) {
  std::vector<Eigen::Vector3f> p_W;
  p_W.reserve(indices.size());
  const Eigen::Isometry3f X_WS = params_.X_WS.cast<float>();
  for (int i : indices) p_W.push_back(X_WS * cloud.points[static_cast<std::size_t>(i)]);
  if (params_.human_voxel > 0) p_W = cloud::VoxelCentroids(p_W, static_cast<float>(params_.human_voxel));
  const Eigen::Matrix3d R_WS = params_.X_WS.linear();
  cell::HumanPoints& human = out->human;
  human.stamp_ns = stamp_ns;
  human.voxel_size = params_.human_voxel;
  human.means.resize(3, static_cast<Eigen::Index>(p_W.size()));
  human.covariances.resize(p_W.size());
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    // The noise of a point measured where the voxel's centroid is: the
    // centroid of several points is no worse measured than one of them.
    const Eigen::Vector3f p_S = (X_SW_ * p_W[i].cast<double>()).cast<float>();
    human.means.col(static_cast<Eigen::Index>(i)) = p_W[i].cast<double>();
    human.covariances[i] = R_WS * cloud::PointCovariance(params_.noise, p_S) * R_WS.transpose();
  }
  // Their motion: without a self-filter the robot's points are among them
  // (and would make parts of their own): the parts are left alone (the next
  // frame predicts them over the longer gap), this frame's points are not
  // tracked.
  if (!track) return;
  std::vector<Eigen::Vector3d> means(static_cast<std::size_t>(human.size()));
  for (std::size_t i = 0; i < means.size(); ++i) means[i] = human.means.col(static_cast<Eigen::Index>(i));
  const std::vector<int> part_of = motion_.Update(means, stamp_ns);
  std::vector<int> motion_of(motion_.parts().size(), -1);
  for (std::size_t k = 0; k < motion_.parts().size(); ++k) {
    const std::optional<PartVelocity> v = motion_.VelocityOf(k);
    if (!v) continue;
    motion_of[k] = static_cast<int>(human.motions.size());
    human.motions.push_back({v->velocity, v->covariance, motion_.parts()[k].id});
  }
  human.motion_of.assign(means.size(), -1);
  for (std::size_t i = 0; i < part_of.size(); ++i) {
    if (part_of[i] >= 0) human.motion_of[i] = motion_of[static_cast<std::size_t>(part_of[i])];
  }
  if (human.motions.empty()) human.motion_of.clear();  // as FromHumanPoints: empty when none is tracked
}

StageOutput CloudStage::Process(cloud::Cloud* cloud, const std::optional<Eigen::VectorXd>& q, int64_t stamp_ns,
                                const std::vector<Eigen::VectorXd>& around) {
  StageOutput out;
  Crop(cloud, &out);
  std::vector<cloud::Sphere> spheres;
  if (q) spheres = RobotSpheres(*q, around);
  out.self_filtered = !spheres.empty();
  const cloud::Result r = pipeline_.Process(*cloud, spheres);
  out.table_found = r.table.found;
  out.table_points = r.table.points;
  out.clusters = static_cast<int>(r.obstacles.size());

  const Eigen::Isometry3d& X_WS = params_.X_WS;
  std::vector<ClusterObservation> obs;
  obs.reserve(r.obstacles.size());
  std::vector<Eigen::Vector3f> points_W;
  std::vector<int> all;
  const Eigen::Vector3f up_W = Eigen::Vector3f::UnitZ();
  for (const cloud::Obstacle& o : r.obstacles) {
    ClusterObservation c;
    c.box_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    c.box_max = -c.box_min;
    points_W.clear();
    for (int i : o.indices) {
      const Eigen::Vector3d p = X_WS * cloud->points[static_cast<std::size_t>(i)].cast<double>();
      points_W.push_back(p.cast<float>());
      c.centroid += p;
      c.box_min = c.box_min.cwiseMin(p);
      c.box_max = c.box_max.cwiseMax(p);
    }
    c.points = static_cast<int>(o.indices.size());
    c.centroid /= std::max(1, c.points);
    all.resize(points_W.size());
    std::iota(all.begin(), all.end(), 0);
    const cloud::OrientedBox b = cloud::FitOrientedBox(points_W, all, &up_W);
    const Eigen::Matrix3f R_WB = b.orientation.toRotationMatrix();
    c.box.centre = b.centre.cast<double>();
    c.box.yaw = std::atan2(static_cast<double>(R_WB(1, 0)), static_cast<double>(R_WB(0, 0)));
    c.box.half_extents = b.half_extents.cast<double>();
    obs.push_back(c);
  }
  // Without the robot's pose the robot's own points are among the clusters
  // and would merge with, and move, the tracks of real objects: such a
  // frame does not update the tracker, and all its clusters count as human
  // (cautious); the static obstacles already known stay published.
  const bool track = !robot_ || out.self_filtered;
  const std::vector<int> track_of = track ? tracker_.Update(obs, stamp_ns) : std::vector<int>(obs.size(), -1);
  std::vector<int> human;
  for (std::size_t c = 0; c < obs.size(); ++c) {
    if (!track || tracker_.IsHuman(tracker_.tracks()[static_cast<std::size_t>(track_of[c])])) {
      human.insert(human.end(), r.obstacles[c].indices.begin(), r.obstacles[c].indices.end());
    }
  }
  HumanPoints(*cloud, human, track, stamp_ns, &out);
  for (const Track& t : tracker_.tracks()) {
    if (t.cls != TrackClass::kStatic) continue;
    cell::ObstacleBox s;
    s.id = t.id;
    s.centre = t.mean_box.centre;
    s.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(t.mean_box.yaw, Eigen::Vector3d::UnitZ()));
    s.half_extents = t.mean_box.half_extents.cwiseMax(0.0);
    s.points = t.last.points;
    s.first_seen_ns = t.first_seen_ns;
    out.obstacles.push_back(s);
  }
  return out;
}

}  // namespace iplan::cloud_service
